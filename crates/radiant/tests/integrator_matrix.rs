//! Every integrator in every configuration on scenes of known radiance, in the spirit of
//! pbrt-v4's `integrators_test.cpp`: {path, photonmap, sppm, radiosity} × {sobol,
//! independent} samplers × {box, gaussian} pixel filters × {ISO 100, ISO 400} on
//! - the white furnace (`builtin::furnace`, camera at the centre): L = Le/(1 − Kd) = 2;
//! - pbrt's analytic sphere (`fixtures::lit_sphere`, camera inside, off-centre): L = 1;
//! - the same sphere glowing (`fixtures::glowing_sphere`, Le = (1/2, 1/4, 1/8), camera
//!   elsewhere inside): L = Le/(1 − Kd) = (1, 1/2, 1/4).
//!
//! Every check is against the closed form, with a bound from the render's own noise:
//! the spread of its pixels where they are independent (path tracer; the photon mapper
//! given its maps), the spread over independent seeds where pixels share photons
//! (SPPM), the spread of the solved patch radiosities for radiosity (its error is
//! discretisation, not noise). Known biases of small settings are modelled, not
//! hidden in the bound: see `photonmap_matrix`, `sppm_matrix` and `radiosity_matrix`.
//!
//! ISO 400 is rendered with the seed of an ISO 100 render and must be exactly 4 times
//! it, pixel by pixel: the sensor scales the film's readout once (an integrator that
//! scaled its own estimate as well would give 16 times). That also puts the ISO 400
//! mean at 4 L within 4 times the ISO 100 bound.
//!
//! Further: every integrator reports an interrupted render as what the film holds, its
//! images are bit-identical at 1 and 2 threads, and no light leaks out of the furnace.

use std::sync::atomic::Ordering;

use glam::{Vec2, Vec3};
use radiant::Session;
use radiant::color::Rgb;
use radiant::image::Image;
use radiant::math::hash::Pcg32;
use radiant::math::sampling;
use radiant::radiosity::RadiosityIntegrator;
use radiant::radiosity::integrator::solve_session;
use radiant::render::integrator::photon::PhotonMaps;
use radiant::render::integrator::photon::estimate::EstimatePoint;
use radiant::render::integrator::photon::eye::{EyeScratch, gathered_irradiance};
use radiant::render::integrator::{PhotonMapIntegrator, SppmStats};
use radiant::render::{Overrides, Progress, RenderOutput};
use radiant::scene::builtin::{cornell_box, furnace};
use radiant::scene::params::{ParamSet, ParamValue};
use radiant::scene::{DigitRandomization, SamplerKind, SceneDesc};
use radiant_testkit::fixtures::{
    LIT_SPHERE_INTENSITY, LIT_SPHERE_RADIANCE, PixelFilter, SPHERE_ALBEDO, glowing_sphere,
    glowing_sphere_radiance, lit_sphere, with_camera, with_filter, with_integrator, with_iso,
    with_resolution, with_sampler, with_samples, with_seed,
};

/// Image width and height.
const RES: u32 = 16;

/// Standard errors allowed where the error's distribution is close to normal (many
/// pixels or queries): two-sided 7e-6 per check, so the ~150 checks of the matrix fail
/// together with probability ~1e-3 when the code is right.
const Z: f64 = 4.5;

const SAMPLERS: [SamplerKind; 2] = [SamplerKind::Sobol, SamplerKind::Independent];

/// The path tracer also runs with every other sampler: Halton points under each digit
/// randomisation and 16 × 16 jittered strata (its 256 samples, one per stratum) — an
/// unbiased sampler must give the closed form within the pixels' noise.
const PATH_SAMPLERS: [SamplerKind; 6] = [
    SamplerKind::Sobol,
    SamplerKind::Independent,
    SamplerKind::Halton {
        randomization: DigitRandomization::PermuteDigits,
    },
    SamplerKind::Halton {
        randomization: DigitRandomization::Owen,
    },
    SamplerKind::Stratified {
        x: 16,
        y: 16,
        jitter: true,
    },
    SamplerKind::Stratified {
        x: 32,
        y: 8,
        jitter: true,
    },
];

/// One analytic scene: its description and the radiance everywhere inside.
struct Analytic {
    name: &'static str,
    desc: SceneDesc,
    radiance: Rgb,
    /// Emitted radiance of the walls (zero where a point light lights them).
    emitted: Rgb,
    /// The sphere's radius.
    radius: f32,
}

fn analytic_scenes() -> Vec<Analytic> {
    let le = Rgb::new(0.5, 0.25, 0.125);
    vec![
        Analytic {
            name: "furnace",
            desc: furnace(),
            radiance: Rgb::splat(2.0),
            emitted: Rgb::WHITE,
            radius: 100.0,
        },
        Analytic {
            name: "lit-sphere",
            // Off-centre, looking away from the centre at the nearer wall.
            desc: with_camera(
                lit_sphere(),
                Vec3::new(0.4, 0.2, -0.3),
                Vec3::new(0.9, 0.0, 0.5),
                60.0,
            ),
            radiance: Rgb::splat(LIT_SPHERE_RADIANCE),
            emitted: Rgb::BLACK,
            radius: 1.0,
        },
        Analytic {
            name: "glowing-sphere",
            // Off-centre elsewhere, looking across the centre at the far wall.
            desc: with_camera(
                glowing_sphere(le),
                Vec3::new(-0.5, -0.3, 0.2),
                Vec3::new(0.5, 0.2, -0.4),
                75.0,
            ),
            radiance: glowing_sphere_radiance(le),
            emitted: le,
            radius: 1.0,
        },
    ]
}

fn int(v: i32) -> ParamValue {
    ParamValue::Int(vec![v])
}

/// An integrator with the small settings of the matrix.
struct Method {
    name: &'static str,
    /// Samples per pixel (SPPM: iterations).
    spp: u32,
    params: fn(&SceneDesc) -> ParamSet,
}

const PATH: Method = Method {
    name: "path",
    spp: 256,
    params: |_| ParamSet::new().with("maxdepth", int(100)),
};

const PHOTONMAP: Method = Method {
    name: "photonmap",
    spp: 4,
    params: |_| {
        ParamSet::new()
            .with("maxdepth", int(100))
            .with("photons", int(20_000))
            .with("finalgathersamples", int(8))
            .with("globallookup", int(64))
            .with("lookup", int(64))
    },
};

const SPPM: Method = Method {
    name: "sppm",
    spp: 8,
    params: |_| {
        ParamSet::new()
            .with("maxdepth", int(100))
            .with("photonsperiteration", int(4096))
    },
};

const RADIOSITY: Method = Method {
    name: "radiosity",
    spp: 4,
    // Patches of at most 1/150 of the area whatever the scene's scale (242 on these
    // spheres, as edges are split into whole numbers of segments).
    params: |desc| {
        let area: f32 = desc
            .shapes
            .iter()
            .map(|s| s.geometry.surface_area(&s.render_from_object.m))
            .sum();
        ParamSet::new().with("maxpatcharea", ParamValue::Float(vec![area / 150.0]))
    },
};

const METHODS: [&Method; 4] = [&PATH, &PHOTONMAP, &SPPM, &RADIOSITY];

/// One cell of the matrix besides the integrator and the scene.
#[derive(Clone, Copy, Debug)]
struct Config {
    sampler: SamplerKind,
    filter: PixelFilter,
}

fn configs() -> impl Iterator<Item = Config> {
    configs_of(&SAMPLERS)
}

fn configs_of(samplers: &'static [SamplerKind]) -> impl Iterator<Item = Config> {
    samplers.iter().copied().flat_map(|sampler| {
        PixelFilter::ALL
            .into_iter()
            .map(move |filter| Config { sampler, filter })
    })
}

fn case_desc(scene: &SceneDesc, method: &Method, config: Config, iso: f32, seed: u64) -> SceneDesc {
    let desc = with_resolution(scene.clone(), RES, RES);
    let desc = with_filter(with_sampler(desc, config.sampler), config.filter);
    let desc = with_seed(with_samples(with_iso(desc, iso), method.spp), seed);
    with_integrator(desc, method.name, (method.params)(scene))
}

fn case_name(method: &Method, scene: &Analytic, config: Config) -> String {
    format!(
        "{} {} {:?} {:?}",
        method.name, scene.name, config.sampler, config.filter
    )
}

fn session(desc: &SceneDesc) -> Session {
    Session::new(desc, &Overrides::default()).expect("scene builds")
}

/// Per channel: the mean over the pixels and its standard error from their spread.
fn pixel_mean_and_se(img: &Image) -> [(f64, f64); 3] {
    std::array::from_fn(|c| {
        let v: Vec<f64> = img.pixels.iter().map(|p| p[c] as f64).collect();
        mean_and_se(&v)
    })
}

fn mean_and_se(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0);
    (m, (var / n).sqrt())
}

/// The outcome of a test's checks: every line is printed, and the test fails at the
/// end if any failed, so one run shows the whole matrix.
#[derive(Default)]
struct Report {
    lines: Vec<String>,
    failed: usize,
}

impl Report {
    fn check(&mut self, pass: bool, line: String) {
        if !pass {
            self.failed += 1;
        }
        self.lines
            .push(format!("{} {line}", if pass { "ok  " } else { "FAIL" }));
    }

    /// `measured` within `bound` of `expected`.
    fn close(&mut self, case: &str, measured: f64, expected: f64, bound: f64) {
        let pass = (measured - expected).abs() <= bound;
        self.check(
            pass,
            format!(
                "{case}: {measured:.5} vs {expected:.5} (deviation {:+.3} %, bound {:.3} %)",
                100.0 * (measured / expected - 1.0),
                100.0 * bound / expected
            ),
        );
    }

    fn finish(self) {
        for l in &self.lines {
            eprintln!("{l}");
        }
        assert_eq!(
            self.failed,
            0,
            "{} of {} checks failed",
            self.failed,
            self.lines.len()
        );
    }
}

/// Pixels per side of the tiles checked one by one.
const TILE: usize = 4;

/// Standard errors allowed per tile: two-sided 6e-7 per check, for the ~1200 tile
/// checks of the path tracer's and the photon mapper's matrices together.
const Z_TILE: f64 = 5.0;

/// For pixels that are independent estimates of one value: per channel, the image mean
/// within `Z` and every `TILE` × `TILE` tile's mean within `Z_TILE` standard errors of
/// `expect`, each standard error from the spread of all pixels combined with
/// `shared_se`, the known error of `expect` itself.
fn check_independent_pixels(
    report: &mut Report,
    case: &str,
    img: &Image,
    expect: [f64; 3],
    shared_se: [f64; 3],
) {
    let (w, h) = (img.width, img.height);
    for (c, (m, se)) in pixel_mean_and_se(img).into_iter().enumerate() {
        report.close(
            &format!("{case} ch{c}"),
            m,
            expect[c],
            Z * se.hypot(shared_se[c]),
        );
        let pixel_sd = se * ((w * h) as f64).sqrt();
        let tile_se = (pixel_sd / TILE as f64).hypot(shared_se[c]);
        let mut worst = 0.0f64;
        for ty in (0..h).step_by(TILE) {
            for tx in (0..w).step_by(TILE) {
                let mut sum = 0.0;
                for y in ty..ty + TILE {
                    for x in tx..tx + TILE {
                        sum += img.get(x, y)[c] as f64;
                    }
                }
                let mean = sum / (TILE * TILE) as f64;
                worst = worst.max((mean - expect[c]).abs() / tile_se);
            }
        }
        report.check(
            worst <= Z_TILE,
            format!("{case} ch{c}: worst {TILE}x{TILE} tile {worst:.2} standard errors off (bound {Z_TILE})"),
        );
    }
}

/// ISO 400 is the ISO 100 image of the same seed times 4, exactly (4 is a power of two,
/// so the sensor's scale is exact in floating point).
fn check_iso(report: &mut Report, case: &str, iso100: &Image, iso400: &Image) {
    let exact = iso100
        .pixels
        .iter()
        .zip(&iso400.pixels)
        .all(|(a, b)| (*a * 4.0).to_array() == b.to_array());
    let ratio = iso400.mean() / iso100.mean();
    report.check(
        exact,
        format!("{case}: ISO 400 / ISO 100 = {ratio:.6}, 4 exactly in every pixel"),
    );
}

/// Renders ISO 100 and ISO 400 of one case with one seed; returns both outputs.
fn render_both_isos(
    scene: &Analytic,
    method: &Method,
    config: Config,
    seed: u64,
) -> (Session, RenderOutput, Image) {
    let s = session(&case_desc(&scene.desc, method, config, 100.0, seed));
    let out = s.render(&Progress::default());
    let high = session(&case_desc(&scene.desc, method, config, 400.0, seed))
        .render(&Progress::default())
        .film
        .image();
    (s, out, high)
}

/// The path tracer is unbiased, its pixels are independent, and in these spheres every
/// pixel's estimate has the same distribution (a path's value does not depend on where
/// it first meets the wall: every wall point sees the same sphere). So the pixel spread
/// measures each pixel's noise, and the image and every tile must lie within their
/// standard errors of the closed form.
#[test]
fn path_matrix() {
    let mut report = Report::default();
    for (k, scene) in analytic_scenes().iter().enumerate() {
        for (j, config) in configs_of(&PATH_SAMPLERS).enumerate() {
            let case = case_name(&PATH, scene, config);
            let seed = (2 * PATH_SAMPLERS.len() * k + j) as u64;
            let (_, out, high) = render_both_isos(scene, &PATH, config, seed);
            let img = out.film.image();
            let expect = scene.radiance.to_array().map(|l| l as f64);
            check_independent_pixels(&mut report, &case, &img, expect, [0.0; 3]);
            check_iso(&mut report, &case, &img, &high);
        }
    }
    report.finish();
}

/// The photon mapper's image, given its maps, is a sum of independent pixel estimates:
/// emission and next-event estimation are exact in expectation, and the final gather
/// reads the irradiance precomputed at the global map's photons (Christensen 1999)
/// where its rays land. In these spheres the reflected light of the walls, L − Le, is
/// uniform, and from any wall point cosine-distributed gather rays land uniformly over
/// the sphere (the form factor to any wall element is its share of the area), so the
/// precomputed irradiance enters every pixel as Kd · Kd · mean(E_pre)/π, where the
/// exact value is Kd² (L − Le). Its relative error β — noise of the map shared by all
/// pixels, and the bias of small photon counts — is measured here from the maps
/// themselves: the mean of the precomputed irradiance at 20 000 uniform points of the
/// sphere, read by the same lookup the gather rays use, against π (L − Le). The image
/// must then be L + Kd² (L − Le) β within its pixel noise and that measurement's.
///
/// The bias: an irradiance estimate taken at a photon counts that photon at the
/// kernel's centre (cone weight 1, three times a photon's mean weight in the cone), so
/// with n̄ photons in the estimate it reads high by 3/n̄ (n̄ ≈ 37 here: 8 %); reading the
/// nearest precomputed point favours sparse regions, whose estimates are low, which
/// takes back about half, a covariance of second order in the counts' fluctuation
/// (β = 3 to 4 % measured). So β must lie between 0 and 3/n̄; it vanishes as the
/// photons grow (consistency) and moves the image by Kd² (L − Le) β / L ≈ 0.4 to 1 %.
#[test]
fn photonmap_matrix() {
    let mut report = Report::default();
    let albedo2 = (SPHERE_ALBEDO * SPHERE_ALBEDO) as f64;
    for (k, scene) in analytic_scenes().iter().enumerate() {
        for (j, config) in configs().enumerate() {
            let case = case_name(&PHOTONMAP, scene, config);
            let (s, out, high) = render_both_isos(scene, &PHOTONMAP, config, (4 * k + j) as u64);
            let img = out.film.image();
            let cache = precomputed_irradiance_error(&s, scene);
            for c in 0..3 {
                let slack = Z * cache.se[c];
                report.check(
                    -slack < cache.beta[c] && cache.beta[c] < cache.self_bias + slack,
                    format!(
                        "{case} ch{c}: precomputed irradiance {:+.2} % ± {:.2} %, within the own-photon bias {:.2} %",
                        100.0 * cache.beta[c],
                        100.0 * cache.se[c],
                        100.0 * cache.self_bias
                    ),
                );
            }
            let reflected = |c: usize| (scene.radiance[c] - scene.emitted[c]) as f64;
            let expect = std::array::from_fn(|c| {
                scene.radiance[c] as f64 + albedo2 * reflected(c) * cache.beta[c]
            });
            let shared = std::array::from_fn(|c| albedo2 * reflected(c) * cache.se[c]);
            check_independent_pixels(&mut report, &case, &img, expect, shared);
            check_iso(&mut report, &case, &img, &high);
        }
    }
    report.finish();
}

/// The measured error of a photon-map session's precomputed irradiance.
struct CacheError {
    /// Relative error of the mean precomputed irradiance per channel.
    beta: [f64; 3],
    /// Standard error of `beta` from the spread of the queries.
    se: [f64; 3],
    /// The largest bias the own photon can cause: 3 / n̄ (cone kernel).
    self_bias: f64,
}

/// Builds the session's maps again (the same photons: same settings, sampler and seed)
/// and reads the irradiance at uniform points of the sphere as a gather ray landing
/// there does.
fn precomputed_irradiance_error(session: &Session, scene: &Analytic) -> CacheError {
    let integrator = session
        .integrator_as::<PhotonMapIntegrator>()
        .expect("a photon-map session");
    let settings = integrator.settings;
    let ctx = &session.ctx;
    let seed = settings.seed.unwrap_or(ctx.seed);
    let maps = PhotonMaps::build(
        &ctx.world,
        &settings,
        ctx.sampler,
        seed,
        &Progress::default(),
    );
    assert!(maps.irradiance.is_some(), "final gathering precomputes");
    let mut scratch = EyeScratch::new(&maps);
    let mut rng = Pcg32::new(17, 29);
    let queries = 20_000;
    let mut sum = [0.0f64; 3];
    let mut sum2 = [0.0f64; 3];
    for _ in 0..queries {
        let d = sampling::uniform_sphere(Vec2::new(rng.uniform(), rng.uniform()));
        let at = EstimatePoint {
            p: d * scene.radius,
            n: -d,
            two_sided: false,
        };
        let e = gathered_irradiance(&maps, &at, &mut scratch);
        for c in 0..3 {
            sum[c] += e[c] as f64;
            sum2[c] += (e[c] as f64).powi(2);
        }
    }
    let n = queries as f64;
    let area = 4.0 * std::f64::consts::PI * (scene.radius as f64).powi(2);
    let density = maps.global.len() as f64 / area;
    let in_estimate = (density * std::f64::consts::PI * maps.max_r2 as f64)
        .min(settings.global_lookup as f64 - 2.0);
    let mut out = CacheError {
        beta: [0.0; 3],
        se: [0.0; 3],
        self_bias: 3.0 / in_estimate,
    };
    for c in 0..3 {
        let exact = std::f64::consts::PI * (scene.radiance[c] - scene.emitted[c]) as f64;
        let mean = sum[c] / n;
        let var = (sum2[c] / n - mean * mean).max(0.0) * n / (n - 1.0);
        out.beta[c] = mean / exact - 1.0;
        out.se[c] = (var / n).sqrt() / exact;
    }
    out
}

/// Independently seeded renders per SPPM configuration.
const SPPM_SEEDS: u64 = 8;

/// Student's t for 14 degrees of freedom at two-sided 1e-4.
const T14: f64 = 5.36;

/// SPPM's density estimate is unbiased for a uniform photon density at any radius:
/// its update τ' = (τ + Φ) R'²/R² makes τ_k / R_k² the sum over iterations of the flux
/// gathered within that iteration's radius over its square, and each radius is fixed
/// before its iteration's photons are traced, so every term's expectation is the
/// density times π (the shrinking, which follows the photon counts, only changes the
/// variance).
///
/// The one bias is the wall's curvature: a photon counts at a visible point only if it
/// arrived on that point's side of the tangent plane there, and a photon that landed
/// at chord distance d, arriving cosine-distributed about its own normal, which is
/// tilted by 2 asin(d/2R), lies beyond that plane with probability (1 − cos)/2 =
/// d²/(4R²). Over the disc (a cap of chord radius r has area πr² exactly) that loses
/// r²/(8R²) of the photons' light Kd (L − Le), at most `curvature_loss` at the initial
/// radius r₀ (the default r₀ is a few pixel footprints at the bounding radius √3 R,
/// the camera being near the centre; the bound is computed from the r₀ the render
/// reports). The expected mean lies in [L − that, L].
///
/// The pixels share photons, so the pixel spread understates the noise of the image
/// mean (2 to 4 times here); the noise is measured instead from `SPPM_SEEDS`
/// independently seeded renders per configuration, pooled over a sampler's two filters
/// (the filter does not change it; the sampler does): 14 degrees of freedom, a bound
/// of `T14` standard errors.
#[test]
fn sppm_matrix() {
    let mut report = Report::default();
    let mut seed = 0u64;
    for scene in &analytic_scenes() {
        for sampler in SAMPLERS {
            // Per filter: the image means of every seed, per channel.
            let mut means: Vec<(Config, Vec<[f64; 3]>)> = Vec::new();
            let mut initial_radius = 0.0;
            for filter in PixelFilter::ALL {
                let config = Config { sampler, filter };
                let mut per_seed = Vec::new();
                for s in 0..SPPM_SEEDS {
                    let img = if s == 0 {
                        let (_, out, high) = render_both_isos(scene, &SPPM, config, seed);
                        initial_radius = out.stats.get::<SppmStats>().expect("SPPM").initial_radius;
                        let img = out.film.image();
                        check_iso(&mut report, &case_name(&SPPM, scene, config), &img, &high);
                        img
                    } else {
                        session(&case_desc(&scene.desc, &SPPM, config, 100.0, seed))
                            .render(&Progress::default())
                            .film
                            .image()
                    };
                    seed += 1;
                    per_seed.push(pixel_mean_and_se(&img).map(|(m, _)| m));
                }
                means.push((config, per_seed));
            }
            for c in 0..3 {
                let mut squares = 0.0;
                let mut dof = 0.0;
                for (_, per_seed) in &means {
                    let v: Vec<f64> = per_seed.iter().map(|m| m[c]).collect();
                    let (m, _) = mean_and_se(&v);
                    squares += v.iter().map(|x| (x - m).powi(2)).sum::<f64>();
                    dof += (v.len() - 1) as f64;
                }
                let se = (squares / dof / SPPM_SEEDS as f64).sqrt();
                let loss = curvature_loss(scene, c, initial_radius);
                for (config, per_seed) in &means {
                    let v: Vec<f64> = per_seed.iter().map(|m| m[c]).collect();
                    let (m, _) = mean_and_se(&v);
                    let case = case_name(&SPPM, scene, *config);
                    let l = scene.radiance[c] as f64;
                    report.close(
                        &format!("{case} ch{c}"),
                        m,
                        l - loss / 2.0,
                        loss / 2.0 + T14 * se,
                    );
                }
            }
        }
    }
    report.finish();
}

/// The most light SPPM's tangent-plane test can lose to the sphere's curvature at
/// gather radius `radius` (or gain on the far side of the wall): Kd (L − Le) r²/(8R²).
fn curvature_loss(scene: &Analytic, channel: usize, radius: f32) -> f64 {
    let photons = SPHERE_ALBEDO as f64 * (scene.radiance[channel] - scene.emitted[channel]) as f64;
    photons * (radius as f64 / scene.radius as f64).powi(2) / 8.0
}

/// Radiosity solves a discretised problem to its tolerance: its error is the mesh's,
/// not noise. On a closed mesh of one reflectance ρ whose form-factor rows sum to one,
/// energy fixes the area-weighted mean radiosity: Σ A B = ρ (Φ + Σ A B), with Φ the
/// power arriving from the lights, so the mean radiance is ρ Φ / ((1 − ρ) π A). For an
/// emitting mesh Φ/A = π Le (as its own emission is shot): Le / (1 − ρ) on any mesh,
/// exactly as the analytic sphere. For the point light Φ = 4π I and the mean is
/// ρ 4 I / ((1 − ρ) A) = 4π / A for I = π, ρ = 1/2: the inscribed polyhedron's area
/// A < 4π makes it brighter than 1, by +1.7 % for this mesh of 242 patches (O(edge²)
/// in general); the patches vary around that mean (+1.4 to +1.9 %) as their distance
/// from the light does. The test solves the session's mesh again and checks that mean to the
/// solver's tolerance; every pixel of every configuration must lie within the range of
/// the patch radiances (the display interpolates between patches with non-negative
/// weights, and the filters' weights are positive).
#[test]
fn radiosity_matrix() {
    let mut report = Report::default();
    for (k, scene) in analytic_scenes().iter().enumerate() {
        let base = config_zero();
        let s = session(&case_desc(&scene.desc, &RADIOSITY, base, 100.0, 0));
        let integrator = s.integrator_as::<RadiosityIntegrator>().expect("radiosity");
        let solved = solve_session(
            &s.ctx.world,
            &integrator.scene,
            &integrator.settings,
            &Progress::default(),
        );
        let mesh = solved.scene(&integrator.scene);
        let display = solved.solution.display_radiosity(&mesh.patches);
        let area = mesh.patches.total_area();
        let albedo = SPHERE_ALBEDO as f64;
        let mut range = [(f64::INFINITY, f64::NEG_INFINITY); 3];
        for c in 0..3 {
            let radiance = |i: usize| display[i][c] / std::f64::consts::PI;
            let mean = (0..mesh.patches.len())
                .map(|i| mesh.patches.patches[i].area * radiance(i))
                .sum::<f64>()
                / area;
            // Exitance of the walls' own emission, and the point light's power per area.
            let exitance = std::f64::consts::PI * scene.emitted[c] as f64;
            let delta = if scene.emitted == Rgb::BLACK {
                4.0 * std::f64::consts::PI * LIT_SPHERE_INTENSITY as f64 / area
            } else {
                0.0
            };
            let expect = (exitance + albedo * delta) / ((1.0 - albedo) * std::f64::consts::PI);
            let case = format!(
                "radiosity {} ({} patches) ch{c}: area-weighted mean",
                scene.name,
                mesh.patches.len()
            );
            report.close(&case, mean, expect, integrator.settings.tolerance * expect);
            for i in 0..mesh.patches.len() {
                range[c].0 = range[c].0.min(radiance(i));
                range[c].1 = range[c].1.max(radiance(i));
            }
            eprintln!(
                "radiosity {} ch{c}: closed form {:.5}, mesh mean {expect:.5}, patches {:.5} .. {:.5}",
                scene.name, scene.radiance[c], range[c].0, range[c].1
            );
        }
        for (j, config) in configs().enumerate() {
            let case = case_name(&RADIOSITY, scene, config);
            let (_, out, high) = render_both_isos(scene, &RADIOSITY, config, (4 * k + j) as u64);
            let img = out.film.image();
            for (c, &(lo, hi)) in range.iter().enumerate() {
                // Rounding of the f32 display values.
                let (lo, hi) = (lo * (1.0 - 1e-5), hi * (1.0 + 1e-5));
                let outside = img
                    .pixels
                    .iter()
                    .filter(|p| !(lo..=hi).contains(&(p[c] as f64)))
                    .count();
                let (m, _) = pixel_mean_and_se(&img)[c];
                report.check(
                    outside == 0,
                    format!(
                        "{case} ch{c}: mean {m:.5} ({:+.3} % from the closed form), {outside} pixels outside the patch range",
                        100.0 * (m / scene.radiance[c] as f64 - 1.0)
                    ),
                );
            }
            check_iso(&mut report, &case, &img, &high);
        }
    }
    report.finish();
}

fn config_zero() -> Config {
    Config {
        sampler: SamplerKind::Sobol,
        filter: PixelFilter::Box,
    }
}

/// `method` with `spp` samples per pixel instead of its own.
fn with_spp(method: &Method, spp: u32) -> Method {
    Method {
        name: method.name,
        spp,
        params: method.params,
    }
}

/// Cancelled from the snapshot callback after the first snapshot (one sample per pixel;
/// SPPM: one iteration), every integrator stops there and says so: `interrupted`, and
/// `spp_done` is what every pixel of the film holds and what the snapshot showed, and
/// the image is the snapshot's.
#[test]
fn interrupted_renders_report_what_the_film_holds() {
    for method in METHODS {
        let method = with_spp(method, 8);
        let desc = case_desc(&furnace(), &method, config_zero(), 100.0, 0);
        let s = session(&desc);
        let progress = Progress::default();
        let mut first: Option<(u32, Image)> = None;
        let out = s.render_with_snapshots(&progress, &mut |n, film| {
            if first.is_none() {
                first = Some((n, film.image()));
                progress.cancel.store(true, Ordering::Relaxed);
            }
        });
        let (n, snapshot) = first.expect("a snapshot before the end");
        let held: Vec<u32> = out.film.pixels.iter().map(|p| p.samples).collect();
        eprintln!(
            "{}: snapshot at {n}, spp_done {}, interrupted {}, film holds {}..{}",
            method.name,
            out.spp_done,
            out.interrupted,
            held.iter().min().unwrap(),
            held.iter().max().unwrap()
        );
        assert!(out.interrupted, "{}", method.name);
        assert_eq!(n, 1, "{}", method.name);
        assert_eq!(out.spp_done, n, "{}", method.name);
        assert!(held.iter().all(|&h| h == out.spp_done), "{}", method.name);
        assert_eq!(out.film.image(), snapshot, "{}", method.name);
    }
}

/// Every integrator's image of a small Cornell box is bit-identical at 1 and 2 threads.
#[test]
fn images_are_identical_at_one_and_two_threads() {
    let box16 = with_resolution(cornell_box(), RES, RES);
    for method in METHODS {
        let method = with_spp(method, 4);
        let desc = case_desc(&box16, &method, config_zero(), 100.0, 3);
        let s = session(&desc);
        let (one, two) = (render_on_threads(&s, 1), render_on_threads(&s, 2));
        let bits = |img: &Image| -> Vec<[u32; 3]> {
            img.pixels
                .iter()
                .map(|p| p.to_array().map(f32::to_bits))
                .collect()
        };
        assert!(one.mean() > 0.0, "{}", method.name);
        assert!(bits(&one) == bits(&two), "{}: images differ", method.name);
    }
    for sampler in PATH_SAMPLERS {
        let config = Config {
            sampler,
            ..config_zero()
        };
        let desc = case_desc(&box16, &with_spp(&PATH, 4), config, 100.0, 3);
        let s = session(&desc);
        assert!(
            render_on_threads(&s, 1) == render_on_threads(&s, 2),
            "path with {sampler:?}: images differ"
        );
    }
}

fn render_on_threads(s: &Session, threads: usize) -> Image {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| s.render(&Progress::default())).film.image()
}

/// The furnace emits and reflects only inwards: seen from outside (the scene has no
/// opening to look in through) it is black, exactly, for the path tracer, the photon
/// mapper and radiosity: no photon, shadow ray or patch leaks through the wall. SPPM
/// counts at an outer visible point the photons of the inner side that arrived beyond
/// its tangent plane (see `sppm_matrix`), which reads up to the curvature term
/// Kd (L − Le) r₀²/(8R²) there: its expectation is at most that, and the image mean
/// (about half of the pixels see the sphere) must stay below it.
#[test]
fn the_furnace_is_black_from_outside() {
    let outside = with_camera(furnace(), Vec3::new(30.0, 20.0, -250.0), Vec3::ZERO, 60.0);
    let inside = &analytic_scenes()[0];
    for method in METHODS {
        let desc = case_desc(&outside, &with_spp(method, 4), config_zero(), 100.0, 0);
        let out = session(&desc).render(&Progress::default());
        let img = out.film.image();
        let lit = img.pixels.iter().filter(|p| !p.is_black()).count();
        match out.stats.get::<SppmStats>() {
            Some(stats) => {
                let bound = curvature_loss(inside, 1, stats.initial_radius);
                eprintln!(
                    "sppm outside: mean {:.5}, curvature bound {bound:.5}, {lit} pixels lit",
                    img.mean()
                );
                assert!(
                    img.mean() <= bound,
                    "sppm: {} outside the furnace",
                    img.mean()
                );
            }
            None => assert_eq!(lit, 0, "{}: {lit} pixels not black", method.name),
        }
    }
}
