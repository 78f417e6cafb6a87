//! Solvers against enclosures.json with the exact factors given.

use std::ops::ControlFlow;

use radiant_radiosity::solve::diagnostics::{energy_balance, irradiance};
use radiant_radiosity::{
    AlwaysVisible, FormFactorMatrix, IterationSettings, PatchSet, ProgressiveSettings,
    ShooterSelection, ShootingFactors, solve_gauss_seidel, solve_jacobi, solve_progressive,
};
use serde_json::Value;

use crate::common::{case, f64s, matrix_rows, max_abs_difference, placeholder_set, rgb_rows};

const MATRIX_CASES: [&str; 5] = [
    "sphere_bands",
    "cube_distinct",
    "cube_all_emit",
    "box_cornell_closed",
    "cornell_empty_coarse",
];

fn exact_system(name: &str) -> (Value, PatchSet, FormFactorMatrix<f64>) {
    let c = case(name);
    let set = placeholder_set(&f64s(&c["area"]), &rgb_rows(&c["E"]), &rgb_rows(&c["rho"]));
    let f = FormFactorMatrix::from_rows(&matrix_rows(&c["F"])).unwrap();
    (c, set, f)
}

#[test]
fn all_solvers_reproduce_b_from_the_exact_factors() {
    // Requirement: B to 1e-9. The data are double-precision solutions (their closed
    // forms agree to 1e-15); we iterate to a relative change of 1e-14 (Jacobi, Gauss-
    // Seidel) or an unshot fraction of 1e-14 (shooting), so the remaining iteration
    // error is ~1e-14 * max B / (1 - rho_max) < 1e-11 for these cases (max B = 58,
    // rho <= 0.95).
    let settings = IterationSettings {
        tolerance: 1e-14,
        max_iterations: 10_000,
    };
    for name in MATRIX_CASES {
        let (c, set, f) = exact_system(name);
        let b_exact = rgb_rows(&c["B"]);
        let jacobi = solve_jacobi(&set, &f, settings, |_, _| {}).unwrap();
        let seidel = solve_gauss_seidel(&set, &f, settings, |_, _| {}).unwrap();
        let shooting = solve_progressive(
            &set,
            ShootingFactors::Matrix(&f),
            &AlwaysVisible,
            ProgressiveSettings {
                unshot_tolerance: 1e-14,
                ..ProgressiveSettings::default()
            },
            |_| ControlFlow::Continue(()),
        )
        .unwrap();
        assert!(jacobi.converged && seidel.converged && shooting.converged);
        for (solver, b) in [
            ("Jacobi", &jacobi.radiosity),
            ("Gauss-Seidel", &seidel.radiosity),
            ("shooting", &shooting.state.radiosity),
        ] {
            let error = max_abs_difference(b, &b_exact);
            assert!(error < 1e-9, "{name} {solver}: {error:e}");
        }
        // Irradiance H = F B as tabulated.
        let h = irradiance(&f, &seidel.radiosity);
        assert!(
            max_abs_difference(&h, &rgb_rows(&c["H"])) < 1e-9,
            "{name} H"
        );
    }
}

#[test]
fn iteration_counts_are_comparable_to_the_reference() {
    // Our stopping rules (relative change of B < 1e-6; unshot power summed over bands
    // < 1e-6 of the emitted) are not exactly the data file's, whose convention is not
    // stated, so only require the sweeps to agree within 25 % (+2) and the shots, which
    // also depend on the shooting order (which band's power picks the shooter), within
    // 50 % (+2). Measured: sweeps within 2; shots within 3 except the open Cornell box
    // (49 against 35: its light is strongly coloured, so the bands converge at
    // different rates and the stopping band matters).
    let settings = IterationSettings {
        tolerance: 1e-6,
        max_iterations: 10_000,
    };
    for name in MATRIX_CASES {
        let (c, set, f) = exact_system(name);
        let jacobi = solve_jacobi(&set, &f, settings, |_, _| {})
            .unwrap()
            .iterations();
        let seidel = solve_gauss_seidel(&set, &f, settings, |_, _| {})
            .unwrap()
            .iterations();
        let shots = solve_progressive(
            &set,
            ShootingFactors::Matrix(&f),
            &AlwaysVisible,
            ProgressiveSettings {
                unshot_tolerance: 1e-6,
                ..ProgressiveSettings::default()
            },
            |_| ControlFlow::Continue(()),
        )
        .unwrap()
        .state
        .shots;
        let checks = &c["checks"];
        let reference = [
            (
                "jacobi",
                jacobi,
                checks["jacobi_sweeps"].as_u64().unwrap() as usize,
            ),
            (
                "gauss-seidel",
                seidel,
                checks["gauss_seidel_sweeps"].as_u64().unwrap() as usize,
            ),
            (
                "shooting",
                shots,
                checks["progressive_shots"].as_u64().unwrap() as usize,
            ),
        ];
        for (solver, ours, theirs) in reference {
            println!("{name} {solver}: {ours} (reference {theirs})");
            let allowed = if solver == "shooting" { 0.5 } else { 0.25 };
            assert!(
                ours.abs_diff(theirs) as f64 <= allowed * theirs as f64 + 2.0,
                "{name} {solver}"
            );
        }
    }
}

#[test]
fn shooting_one_band_reproduces_the_unshot_power_trace() {
    // The reference trace shoots by band 0's unshot power; with the same order our
    // unshot fractions must match shot for shot (differences are rounding only).
    for name in MATRIX_CASES {
        let (c, set, f) = exact_system(name);
        let report = solve_progressive(
            &set,
            ShootingFactors::Matrix(&f),
            &AlwaysVisible,
            ProgressiveSettings {
                unshot_tolerance: 0.0,
                max_shots: 20,
                selection: ShooterSelection::Band(0),
                callback_every: 0,
            },
            |_| ControlFlow::Continue(()),
        )
        .unwrap();
        let trace = f64s(&c["checks"]["progressive_unshot_fraction_first20_band0"]);
        for (shot, (ours, theirs)) in report
            .unshot_fraction_per_band
            .iter()
            .zip(&trace)
            .enumerate()
        {
            assert!(
                (ours[0] - theirs).abs() < 1e-12,
                "{name} shot {shot}: {} vs {theirs}",
                ours[0]
            );
        }
        assert_eq!(report.unshot_fraction_per_band.len(), 20);
    }
}

#[test]
fn energy_balance_matches_the_reference() {
    // emitted = absorbed + escaped per band, as tabulated. The tabulated values carry
    // rounding of sums of ~1e5-sized terms (their own imbalance is up to 5e-10 of
    // 8e5), so compare relative to the emitted power at 1e-12.
    for name in MATRIX_CASES {
        let (c, set, f) = exact_system(name);
        let b = rgb_rows(&c["B"]);
        let balance = energy_balance(&set, &f, &b);
        let checks = &c["checks"];
        for band in 0..3 {
            let scale = balance.emitted[band].max(1e-300);
            let reference = |key: &str| checks[key][band].as_f64().unwrap();
            assert!((balance.emitted[band] - reference("emitted_power")).abs() < 1e-12 * scale);
            assert!((balance.absorbed[band] - reference("absorbed_power")).abs() < 1e-12 * scale);
            assert!((balance.escaped[band] - reference("escaped_power")).abs() < 1e-12 * scale);
            assert!(balance.imbalance()[band].abs() < 1e-12 * scale, "{name}");
        }
    }
}

#[test]
fn light_through_the_opening_escapes() {
    // The open Cornell box's front opening is a black sink patch. Dropping it leaves
    // rows that sum to < 1; the solution on the other patches is unchanged (the sink
    // has B = 0) and what used to be absorbed by the sink, A_sink H_sink, now escapes.
    let (c, set, f) = exact_system("cornell_empty_coarse");
    let b = rgb_rows(&c["B"]);
    let h = rgb_rows(&c["H"]);
    let sink = 6;
    let keep: Vec<usize> = (0..7).filter(|&k| k != sink).collect();
    let rows: Vec<Vec<f64>> = keep
        .iter()
        .map(|&i| keep.iter().map(|&j| f.get(i, j)).collect())
        .collect();
    let open_f = FormFactorMatrix::from_rows(&rows).unwrap();
    let open_set = placeholder_set(
        &keep
            .iter()
            .map(|&k| set.patches[k].area)
            .collect::<Vec<_>>(),
        &keep
            .iter()
            .map(|&k| set.patches[k].emission)
            .collect::<Vec<_>>(),
        &keep
            .iter()
            .map(|&k| set.patches[k].reflectance)
            .collect::<Vec<_>>(),
    );
    let solved = solve_gauss_seidel(
        &open_set,
        &open_f,
        IterationSettings {
            tolerance: 1e-14,
            max_iterations: 1000,
        },
        |_, _| {},
    )
    .unwrap();
    let kept_b: Vec<[f64; 3]> = keep.iter().map(|&k| b[k]).collect();
    assert!(max_abs_difference(&solved.radiosity, &kept_b) < 1e-9);
    let balance = energy_balance(&open_set, &open_f, &solved.radiosity);
    for (band, sink_irradiance) in h[sink].iter().enumerate() {
        let sink_absorbed = set.patches[sink].area * sink_irradiance;
        let scale = balance.emitted[band];
        assert!(
            (balance.escaped[band] - sink_absorbed).abs() < 1e-9 * scale,
            "band {band}"
        );
        assert!(balance.imbalance()[band].abs() < 1e-9 * scale);
        // A fair share of the light leaves the open box.
        assert!(balance.escaped[band] > 0.1 * scale);
    }
}

#[test]
fn ambient_term_makes_the_display_exact_in_a_uniform_sphere() {
    // With the sphere's exact factors F_ij = A_j / A and one reflectance everywhere,
    // unshot light spreads uniformly, so the ambient term (Cohen et al. 1988) is the
    // exact remainder: B_i + rho ambient equals the converged B after any number of
    // shots, up to rounding.
    let c = case("sphere_bands");
    let areas = f64s(&c["area"]);
    let emission = rgb_rows(&c["E"]);
    let set = placeholder_set(&areas, &emission, &[[0.6, 0.3, 0.9]; 8]);
    let f = FormFactorMatrix::from_rows(&vec![vec![0.125; 8]; 8]).unwrap();
    let exact = solve_gauss_seidel(
        &set,
        &f,
        IterationSettings {
            tolerance: 1e-15,
            max_iterations: 10_000,
        },
        |_, _| {},
    )
    .unwrap()
    .radiosity;
    let mut seen = Vec::new();
    solve_progressive(
        &set,
        ShootingFactors::Matrix(&f),
        &AlwaysVisible,
        ProgressiveSettings {
            max_shots: 6,
            unshot_tolerance: 0.0,
            callback_every: 1,
            ..ProgressiveSettings::default()
        },
        |state| {
            seen.push(max_abs_difference(&state.display_radiosity(&set), &exact));
            ControlFlow::Continue(())
        },
    )
    .unwrap();
    assert_eq!(seen.len(), 6);
    for (shot, error) in seen.iter().enumerate() {
        assert!(*error < 1e-12, "shot {}: {error:e}", shot + 1);
    }
}
