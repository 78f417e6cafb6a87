//! Solvers against enclosures.json: exact factors given, and factors computed here.

use radiant::math::DVec3;
use radiant::radiosity::report::{closure_error, energy_balance, irradiance, reciprocity};
use radiant::radiosity::shapes::{sphere_interior, uniform_z_rings};
use radiant::radiosity::{
    AlwaysVisible, FormFactorMatrix, IterationSettings, PatchSet, ProgressiveSettings, Quadrature,
    RayCastSettings, RayCaster, ShooterSelection, ShootingFactors, solve_gauss_seidel,
    solve_jacobi, solve_progressive,
};
use serde_json::Value;

use crate::common::{f64s, matrix_rows, rgb_rows, shared_json, vertices};

pub fn case(name: &str) -> Value {
    shared_json("enclosures.json")["cases"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["name"] == name)
        .unwrap_or_else(|| panic!("no case {name}"))
        .clone()
}

/// Patches with the given areas, emission and reflectance but placeholder geometry
/// (squares of the right area far apart): enough for solvers given the factors.
pub fn placeholder_set(areas: &[f64], emission: &[[f64; 3]], reflectance: &[[f64; 3]]) -> PatchSet {
    let mut set = PatchSet::new();
    for (k, &area) in areas.iter().enumerate() {
        let side = area.sqrt();
        let o = DVec3::new(10.0 * k as f64 * side, 0.0, 0.0);
        let corners = [
            o,
            o + DVec3::X * side,
            o + DVec3::new(side, side, 0.0),
            o + DVec3::Y * side,
        ];
        set.add_polygon(&corners, emission[k], reflectance[k])
            .unwrap();
    }
    set
}

fn max_abs_difference(a: &[[f64; 3]], b: &[[f64; 3]]) -> f64 {
    a.iter()
        .zip(b)
        .flat_map(|(x, y)| (0..3).map(move |k| (x[k] - y[k]).abs()))
        .fold(0.0, f64::max)
}

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
            |_| {},
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
            |_| {},
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
            |_| {},
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
fn uniform_sphere_with_factors_computed_here() {
    // Inside a closed convex polyhedron the contour factors of all patches tile each
    // point's hemisphere, so every computed row sums to 1 to rounding; with uniform E
    // and rho the solution is then exactly B = E / (1 - rho), whatever the
    // tessellation. Rounding in the row sums (~1e-15 N) is amplified by
    // rho / (1 - rho) <= 99, so 1e-9 relative is ample.
    let c = case("sphere_uniform");
    for sub in c["cases"].as_array().unwrap() {
        let (e, rho, b) = (
            sub["E"].as_f64().unwrap(),
            sub["rho"].as_f64().unwrap(),
            sub["B"].as_f64().unwrap(),
        );
        let set =
            sphere_interior(1.0, &uniform_z_rings(1.0, 8), 16, |_| ([e; 3], [rho; 3])).unwrap();
        let caster = RayCaster::new(RayCastSettings {
            quadrature: Quadrature::Gauss {
                order: 2,
                grading_levels: 0,
            },
            ..RayCastSettings::default()
        });
        let f = caster.matrix(&set, &AlwaysVisible);
        assert!(closure_error(&f) < 1e-13, "{}", closure_error(&f));
        let settings = IterationSettings {
            tolerance: 1e-14,
            max_iterations: 100_000,
        };
        let seidel = solve_gauss_seidel(&set, &f, settings, |_, _| {}).unwrap();
        let jacobi = solve_jacobi(&set, &f, settings, |_, _| {}).unwrap();
        for solution in [&seidel.radiosity, &jacobi.radiosity] {
            for bi in solution {
                assert!((bi[0] - b).abs() < 1e-9 * b, "rho {rho}: {} vs {b}", bi[0]);
            }
        }
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
        |state| seen.push(max_abs_difference(&state.display_radiosity(&set), &exact)),
    )
    .unwrap();
    assert_eq!(seen.len(), 6);
    for (shot, error) in seen.iter().enumerate() {
        assert!(*error < 1e-12, "shot {}: {error:e}", shot + 1);
    }
}

#[test]
fn sphere_bands_with_factors_computed_here() {
    // The 8 equal-area bands of the unit sphere (cut at z = -1 + k/4), tessellated
    // into rings about 0.03 rad apart in polar angle and 128 meridian segments (0.05
    // rad): 14,080 planar patches. By rotational symmetry every patch of a ring has the
    // same row sums per band, so one row per ring gives the band-to-band factors
    // F_IJ = sum_{r in I} A_r F_rJ / A_I exactly as the full matrix would. The
    // polyhedron is not the sphere: its band factors differ from A_J / A by O(h^2)
    // with h the patch size in radians (measured: the polar band's self-factor is off
    // by 5.9e-3 with 0.09 rad rings, 1.0e-3 with 0.045 rad; the other factors by
    // < 1e-3; at the spacing used here all factors within 3.7e-4 and B within 2.2e-4).
    // The requirement is B within 1e-3 (relative).
    let c = case("sphere_bands");
    let segments = 128;
    let mut heights = vec![-1.0];
    let mut band_of_ring = Vec::new();
    for band in 0..8 {
        let theta_low = (-1.0 + band as f64 / 4.0f64).acos();
        let theta_high = (-1.0 + (band + 1) as f64 / 4.0f64).acos();
        let rings = ((theta_low - theta_high) / 0.03).ceil() as usize;
        for k in 1..=rings {
            let t = k as f64 / rings as f64;
            heights.push((theta_low + t * (theta_high - theta_low)).cos());
            band_of_ring.push(band);
        }
        // The band's top ring lies exactly on its cut plane.
        *heights.last_mut().unwrap() = -1.0 + (band + 1) as f64 / 4.0;
    }
    let rings = band_of_ring.len();
    let set = sphere_interior(1.0, &heights, segments, |_| ([0.0; 3], [0.5; 3])).unwrap();
    let caster = RayCaster::new(RayCastSettings {
        quadrature: Quadrature::Gauss {
            order: 2,
            grading_levels: 0,
        },
        ..RayCastSettings::default()
    });
    let mut band_factors = vec![vec![0.0; 8]; 8];
    let mut band_areas = vec![0.0; 8];
    let mut row = vec![0.0; set.len()];
    for ring in 0..rings {
        let patch = ring * segments;
        caster.row(&set, patch, &AlwaysVisible, &mut row);
        let ring_area = set.patches[patch].area * segments as f64;
        let band = band_of_ring[ring];
        band_areas[band] += ring_area;
        for (j, f) in row.iter().enumerate() {
            band_factors[band][band_of_ring[j / segments]] += ring_area * f;
        }
    }
    for (band, factors) in band_factors.iter_mut().enumerate() {
        factors.iter_mut().for_each(|f| *f /= band_areas[band]);
    }
    let total: f64 = band_areas.iter().sum();
    let mut worst_factor = 0.0f64;
    for factors in &band_factors {
        for (j, f) in factors.iter().enumerate() {
            worst_factor = worst_factor.max((f / (band_areas[j] / total) - 1.0).abs());
        }
    }
    let f = FormFactorMatrix::from_rows(&band_factors).unwrap();
    let set8 = placeholder_set(&band_areas, &rgb_rows(&c["E"]), &rgb_rows(&c["rho"]));
    let solved = solve_gauss_seidel(
        &set8,
        &f,
        IterationSettings {
            tolerance: 1e-14,
            max_iterations: 1000,
        },
        |_, _| {},
    )
    .unwrap();
    let b_exact = rgb_rows(&c["B"]);
    let mut worst = 0.0f64;
    for (ours, exact) in solved.radiosity.iter().zip(&b_exact) {
        for k in 0..3 {
            worst = worst.max((ours[k] - exact[k]).abs() / exact[k]);
        }
    }
    println!(
        "{} patches: band factors off by {worst_factor:.1e}, B off by {worst:.1e} (relative)",
        set.len()
    );
    assert!(worst < 1e-3);
}

/// The cube and closed box cases as patches with their real geometry.
fn polygon_case_set(c: &Value) -> PatchSet {
    let mut set = PatchSet::new();
    let (e, rho) = (rgb_rows(&c["E"]), rgb_rows(&c["rho"]));
    for (k, patch) in c["patches"].as_array().unwrap().iter().enumerate() {
        set.add_polygon(&vertices(&patch["vertices"]), e[k], rho[k])
            .unwrap();
    }
    set
}

#[test]
fn cubes_with_factors_computed_here() {
    // One patch per wall; factors by graded Gauss (6 points, 6 levels: error <= 4e-10
    // on the formfactors.json cases, shared edges included). Requirement: B within 1e-3
    // (relative); the factor error propagates to B at the same order, measured 1e-9.
    let caster = RayCaster::new(RayCastSettings {
        quadrature: Quadrature::Gauss {
            order: 6,
            grading_levels: 6,
        },
        ..RayCastSettings::default()
    });
    for name in ["cube_distinct", "cube_all_emit", "box_cornell_closed"] {
        let c = case(name);
        let set = polygon_case_set(&c);
        let f = caster.matrix(&set, &AlwaysVisible);
        let exact_f = FormFactorMatrix::from_rows(&matrix_rows(&c["F"])).unwrap();
        let factor_error = f
            .values()
            .iter()
            .zip(exact_f.values())
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        let solved = solve_gauss_seidel(
            &set,
            &f,
            IterationSettings {
                tolerance: 1e-14,
                max_iterations: 1000,
            },
            |_, _| {},
        )
        .unwrap();
        let b_exact = rgb_rows(&c["B"]);
        let mut worst = 0.0f64;
        for (ours, exact) in solved.radiosity.iter().zip(&b_exact) {
            for k in 0..3 {
                worst = worst.max((ours[k] - exact[k]).abs() / exact[k].max(1e-3));
            }
        }
        println!("{name}: factors off by {factor_error:.1e}, B by {worst:.1e} (relative)");
        assert!(factor_error < 1e-8);
        assert!(worst < 1e-3);
        let r = reciprocity(&set, &f);
        assert!(r.max_relative < 1e-8, "{name}: {r:?}");
    }
}

#[test]
fn open_cornell_box_with_factors_computed_here() {
    // The coarse open Cornell box: some of its patches are unions of rectangles (the
    // ceiling minus the light hole is four). Factors are computed between the ten
    // rectangles and combined: F_IJ = sum_{p in I} A_p sum_{q in J} F_pq / A_I.
    // Graded Gauss as for the cubes; the tabulated factors are semi-analytic to 1e-15,
    // so ours must match to 1e-8 and B to 1e-3 (measured 2e-10 for both).
    let c = case("cornell_empty_coarse");
    let mut set = PatchSet::new();
    let mut owner = Vec::new();
    for (k, patch) in c["patches"].as_array().unwrap().iter().enumerate() {
        for polygon in patch["polygons"].as_array().unwrap() {
            set.add_polygon(&vertices(&polygon["vertices"]), [0.0; 3], [0.5; 3])
                .unwrap();
            owner.push(k);
        }
    }
    assert_eq!(set.len(), 10);
    let caster = RayCaster::new(RayCastSettings {
        quadrature: Quadrature::Gauss {
            order: 6,
            grading_levels: 6,
        },
        ..RayCastSettings::default()
    });
    let fine = caster.matrix(&set, &AlwaysVisible);
    let areas = f64s(&c["area"]);
    let mut rows = vec![vec![0.0; 7]; 7];
    for p in 0..set.len() {
        for q in 0..set.len() {
            rows[owner[p]][owner[q]] += set.patches[p].area * fine.get(p, q) / areas[owner[p]];
        }
    }
    let exact = matrix_rows(&c["F"]);
    let factor_error = rows
        .iter()
        .flatten()
        .zip(exact.iter().flatten())
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    let f = FormFactorMatrix::from_rows(&rows).unwrap();
    let set7 = placeholder_set(&areas, &rgb_rows(&c["E"]), &rgb_rows(&c["rho"]));
    let solved = solve_gauss_seidel(
        &set7,
        &f,
        IterationSettings {
            tolerance: 1e-14,
            max_iterations: 1000,
        },
        |_, _| {},
    )
    .unwrap();
    let b_error = max_abs_difference(&solved.radiosity, &rgb_rows(&c["B"]));
    println!("open Cornell box: factors off by {factor_error:.1e}, B by {b_error:.1e}");
    assert!(factor_error < 1e-8);
    assert!(b_error < 1e-3);
}
