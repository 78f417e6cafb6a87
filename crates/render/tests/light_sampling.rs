//! Light sampling against the lights' densities, by Pearson's chi-square test
//! (`radiant_testkit::chi2`): every area shape's `sample_li` through the world's light
//! sampler from receivers near, far and at grazing angles, the environment's, and
//! every light's `sample_le` (directions and positions). Delta distributions have no
//! density: their directions and positions are checked to be exact.
//!
//! The density a direction is tested against is what the path tracer's MIS weight
//! uses for a BSDF-sampled ray: the world's first hit along it, the light sampler's
//! probability of that light and the light's `pdf_li` at the hit. A light whose
//! `pdf_li` disagrees with its own sampling fails here; the last test checks that the
//! MIS-weighted estimate of the direct light keeps its mean.

use glam::{Vec2, Vec3};
use radiant_math::color::Rgb;
use radiant_math::hash::Pcg32;
use radiant_math::sampling::{UNIFORM_SPHERE_PDF, power_heuristic, uniform_cone_pdf};
use radiant_math::{Frame, INV_PI, Transform};
use radiant_render::geometry::Ray;
use radiant_render::integrator::direct::{self, ShadingPoint};
use radiant_render::light::{Light, LightLeSample, LightSampleContext, LightShape, SceneSphere};
use radiant_render::material::TransportMode;
use radiant_render::world::{NO_LIGHT, World};
use radiant_scene::builtin::cornell_box;
use radiant_scene::{AreaLightDesc, Geometry, LightDesc, SceneDesc, ShapeDesc};
use radiant_testkit::chi2::{ChiSquareReport, ChiSquareTest, Domain, DomainPoint, SampleInput};

/// Family-wise significance of the whole file: each chi-square test is judged at
/// Šidák's 1 - (1 - ALPHA)^(1 / CHI2_TESTS).
const ALPHA: f64 = 0.01;
/// Every chi-square test in this file: 22 of `sample_li`, 15 of `sample_le`.
const CHI2_TESTS: u32 = 37;
const SAMPLES: u64 = 200_000;

/// Passes unless the report fails at the file's family-wise significance; prints it.
fn check(report: &ChiSquareReport) {
    report.check(ALPHA, CHI2_TESTS);
}

fn scene_of(shapes: Vec<ShapeDesc>, lights: Vec<LightDesc>) -> SceneDesc {
    let mut desc = cornell_box();
    desc.shapes = shapes;
    desc.lights = lights;
    desc
}

/// An emitting shape (radiance 1) of the white diffuse material.
fn emitter(geometry: Geometry, render_from_object: Transform, two_sided: bool) -> ShapeDesc {
    let mut s = cornell_box().shapes.remove(0);
    s.geometry = geometry;
    s.render_from_object = render_from_object;
    s.reverse_orientation = false;
    s.material = 0;
    s.area_light = Some(AreaLightDesc {
        l: Rgb::splat(1.0),
        two_sided,
        image: None,
    });
    s
}

fn world_of(shapes: Vec<ShapeDesc>) -> World {
    World::build(&scene_of(shapes, Vec::new()))
        .expect("the world builds")
        .0
}

fn mesh(positions: Vec<Vec3>, indices: Vec<u32>) -> Geometry {
    Geometry::TriangleMesh {
        positions,
        indices,
        normals: None,
        uvs: None,
    }
}

/// The unit right triangle in z = 0, emitting towards +z.
fn triangle() -> Geometry {
    mesh(vec![Vec3::ZERO, Vec3::X, Vec3::Y], vec![0, 1, 2])
}

/// A planar but irregular quad in z = 0 facing +z: two triangles of different areas that
/// are no parallelogram, so the world makes one mesh light of them, and its test covers
/// the choice of the triangle by area inside the light.
fn planar_quad() -> Geometry {
    Geometry::BilinearMesh {
        positions: vec![
            Vec3::ZERO,
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(1.5, 1.2, 0.0),
        ],
        indices: vec![0, 1, 2, 3],
        normals: None,
        uvs: None,
    }
}

/// A tilted parallelogram (a quad of two triangles, as the Cornell box's light):
/// sampled as one patch.
fn parallelogram() -> Geometry {
    let (p, e1, e2) = (
        Vec3::new(-0.5, -0.3, 0.0),
        Vec3::new(1.2, 0.2, 0.1),
        Vec3::new(0.3, 0.9, -0.2),
    );
    mesh(vec![p, p + e1, p + e1 + e2, p + e2], vec![0, 1, 2, 0, 2, 3])
}

/// An open pyramid of four triangles over the unit square, apex at z = 0.7, facing out:
/// a mesh light whose triangles face different ways.
fn pyramid() -> Geometry {
    mesh(
        vec![
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(1.0, -1.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(-1.0, 1.0, 0.0),
            Vec3::new(0.2, 0.1, 0.7),
        ],
        vec![0, 1, 4, 1, 2, 4, 2, 3, 4, 3, 0, 4],
    )
}

/// A saddle-shaped bilinear patch over [-1, 1]², heights 0 to 0.6, facing about +z.
fn saddle() -> Geometry {
    Geometry::BilinearMesh {
        positions: vec![
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(1.0, -1.0, 0.6),
            Vec3::new(-1.0, 1.0, 0.6),
            Vec3::new(1.0, 1.0, 0.0),
        ],
        indices: vec![0, 1, 2, 3],
        normals: None,
        uvs: None,
    }
}

fn sphere(z_min: f32, z_max: f32, phi_max_deg: f32) -> Geometry {
    Geometry::Sphere {
        radius: 1.0,
        z_min,
        z_max,
        phi_max_deg,
    }
}

fn disk(inner_radius: f32, phi_max_deg: f32) -> Geometry {
    Geometry::Disk {
        height: 0.2,
        radius: 1.0,
        inner_radius,
        phi_max_deg,
    }
}

fn translate(x: f32, y: f32, z: f32) -> Transform {
    Transform::translate(Vec3::new(x, y, z))
}

fn scale(s: f32) -> Transform {
    Transform::scale(Vec3::splat(s)).expect("non-zero scale")
}

fn rotate(degrees: f32, axis: Vec3) -> Transform {
    Transform::rotate(degrees, axis).expect("a rotation")
}

/// A disk placement that is not axis-aligned.
fn tilted() -> Transform {
    translate(0.3, -0.4, 0.5).compose(&rotate(35.0, Vec3::new(1.0, 0.5, 0.0)))
}

/// The light-sampling density of direction `wi` from `ctx`, as MIS evaluates it for a
/// ray found by BSDF sampling: the first hit's light, if it emits towards `ctx`, else
/// the lights at infinity for a ray that escapes.
fn pdf_towards(world: &World, ctx: &LightSampleContext, wi: Vec3) -> f32 {
    let sampler = &world.light_sampler;
    let Some(hit) = world.intersect(&Ray::new(ctx.p, wi), f32::INFINITY) else {
        return (world.lights.iter().enumerate())
            .map(|(i, l)| sampler.pmf(ctx, i) * l.pdf_li(ctx, wi, None))
            .sum();
    };
    if hit.light == NO_LIGHT {
        return 0.0;
    }
    let light = &world.lights[hit.light as usize];
    let Light::Area(area) = light else {
        unreachable!("primitives only carry area lights")
    };
    if area.radiance(hit.ng, hit.uv, -wi).is_black() {
        return 0.0;
    }
    sampler.pmf(ctx, hit.light as usize) * light.pdf_li(ctx, wi, Some(&hit.light_hit()))
}

/// Runs `test` on `sample`, which returns a point and the density the sampling routine
/// claims for it, against `pdf`; the claimed density must be `pdf`'s at the point (to
/// `relative`, or both zero) for all but `tolerated` samples.
fn run_consistent<P: DomainPoint>(
    test: ChiSquareTest,
    (relative, tolerated): (f32, u64),
    mut sample: impl FnMut(SampleInput) -> Option<(P, f32)>,
    pdf: impl Fn(P) -> f32,
) {
    let (mut checked, mut disagree) = (0u64, 0u64);
    let mut worst = None;
    let report = test.run(
        |u| {
            let (p, own) = sample(u)?;
            let found = pdf(p);
            checked += 1;
            if (own - found).abs() > relative * own.max(found) {
                disagree += 1;
                worst = Some((p, own, found));
            }
            Some(p)
        },
        &pdf,
    );
    check(&report);
    assert!(
        disagree <= tolerated,
        "{}: {disagree} of {checked} samples claim a density other than the pdf's, e.g. {worst:?}",
        report.name
    );
}

/// Next-event estimation's directions from `receiver` (a light chosen by the world's
/// sampler, then a direction on it) against [`pdf_towards`]: the sampled point must
/// be where a ray along its direction meets the light first, with the same density.
fn li_on(test: ChiSquareTest, world: &World, receiver: Vec3) {
    let ctx = LightSampleContext::at_point(receiver);
    let scene = world.scene_sphere();
    // The density is evaluated where a ray along the sampled direction meets the light,
    // which differs from the sampled point by round-off (amplified by 1/cos where the
    // light is seen edge-on); a ray aimed at a sample an ulp from the light's rim may
    // miss it.
    run_consistent(
        test,
        (1e-2, 5 + SAMPLES / 50_000),
        |u| {
            let chosen = world.light_sampler.sample(&ctx, u.u1)?;
            let s = world.lights[chosen.index].sample_li(&ctx, u.u2, scene)?;
            assert!(!s.delta && !s.at_infinity);
            Some((s.wi, chosen.pmf * s.pdf))
        },
        |wi| pdf_towards(world, &ctx, wi),
    );
}

fn li_test(name: &str, seed: u64) -> ChiSquareTest {
    ChiSquareTest::new(name, Domain::Sphere)
        .samples(SAMPLES)
        .seed(seed)
        .max_refinement(6)
}

fn li(name: &str, world: &World, receiver: Vec3, seed: u64) {
    li_on(li_test(name, seed), world, receiver);
}

/// A finer grid for lights that cover a small solid angle.
fn li_far(name: &str, world: &World, receiver: Vec3, seed: u64) {
    li_on(li_test(name, seed).resolution(384, 192), world, receiver);
}

/// Seen at a grazing angle, a planar light is a sliver a few hundredths wide in cos θ
/// (the rows): rows fine enough to resolve its steep density (∝ 1/|cos θ|³).
fn li_grazing(name: &str, world: &World, receiver: Vec3, seed: u64) {
    li_on(li_test(name, seed).resolution(128, 512), world, receiver);
}

#[test]
fn triangle_light_sample_li_follows_pdf_li() {
    let world = world_of(vec![emitter(triangle(), Transform::IDENTITY, false)]);
    li("triangle_near", &world, Vec3::new(0.3, 0.25, 0.15), 1);
    li_far("triangle_far", &world, Vec3::new(0.2, 0.4, 5.0), 2);
    li_grazing("triangle_grazing", &world, Vec3::new(1.3, 0.6, 0.02), 3);
    let two_sided = world_of(vec![emitter(triangle(), Transform::IDENTITY, true)]);
    li(
        "triangle_two_sided_behind",
        &two_sided,
        Vec3::new(0.3, 0.2, -0.4),
        4,
    );
}

#[test]
fn quad_and_bilinear_lights_sample_li_follow_pdf_li() {
    let quad = world_of(vec![emitter(planar_quad(), Transform::IDENTITY, false)]);
    assert!(
        matches!(&quad.lights[..], [Light::Area(a)] if matches!(a.shape, LightShape::Mesh(_))),
        "an irregular planar quad is one mesh light"
    );
    li("quad_near", &quad, Vec3::new(0.8, 0.5, 0.3), 5);
    li_grazing("quad_grazing", &quad, Vec3::new(-0.5, 0.5, 0.05), 6);
    let par = world_of(vec![emitter(parallelogram(), Transform::IDENTITY, false)]);
    assert!(
        matches!(&par.lights[..], [Light::Area(a)] if matches!(a.shape, LightShape::Parallelogram { .. })),
        "two triangles forming a parallelogram are one parallelogram light"
    );
    li("parallelogram_near", &par, Vec3::new(0.2, 0.3, 0.4), 38);
    li_grazing("parallelogram_grazing", &par, Vec3::new(1.4, 0.4, 0.12), 39);
    let pyr = world_of(vec![emitter(pyramid(), Transform::IDENTITY, false)]);
    assert_eq!(pyr.lights.len(), 1, "a mesh is one light");
    li("mesh_near", &pyr, Vec3::new(1.1, 0.6, 0.5), 40);
    li_far("mesh_far", &pyr, Vec3::new(-0.8, 2.5, 4.0), 41);
    let patch = world_of(vec![emitter(saddle(), Transform::IDENTITY, false)]);
    assert!(matches!(
        &patch.lights[..],
        [Light::Area(a)] if matches!(a.shape, LightShape::Bilinear { .. })
    ));
    li("bilinear_near", &patch, Vec3::new(0.1, 0.2, 1.0), 7);
    li_far("bilinear_far", &patch, Vec3::new(0.5, -0.3, 6.0), 8);
    li("bilinear_oblique", &patch, Vec3::new(2.5, 0.5, 1.5), 9);
}

#[test]
fn sphere_light_sample_li_follows_pdf_li() {
    let centre = Vec3::new(0.5, -0.2, 0.3);
    let placed = translate(centre.x, centre.y, centre.z);
    let world = world_of(vec![emitter(sphere(-1.0, 1.0, 360.0), placed, false)]);
    let towards = |d: Vec3, r: f32| centre + d.normalize() * r;
    li(
        "sphere_near",
        &world,
        towards(Vec3::new(0.9, 0.6, 0.8), 1.6),
        10,
    );
    li_far(
        "sphere_far",
        &world,
        towards(Vec3::new(-0.3, 0.2, 0.7), 8.0),
        11,
    );
    // Inside a sphere of radius 2 that emits inwards: area sampling.
    let mut inward = emitter(sphere(-1.0, 1.0, 360.0), placed.compose(&scale(2.0)), false);
    inward.reverse_orientation = true;
    let inside = world_of(vec![inward]);
    li(
        "sphere_inside",
        &inside,
        centre + Vec3::new(0.5, -0.3, 0.9),
        12,
    );
    // A cut sphere is area sampled, here from inside, where no point is seen edge-on.
    // (From outside the density per solid angle grows without bound at the silhouette,
    // which cell quadrature cannot integrate to the precision the test needs.)
    let mut cut = emitter(sphere(-0.5, 0.8, 270.0), Transform::IDENTITY, false);
    cut.reverse_orientation = true;
    let cut = world_of(vec![cut]);
    li("partial_sphere_inside", &cut, Vec3::new(0.2, -0.1, 0.1), 13);
}

#[test]
fn disk_light_sample_li_follows_pdf_li() {
    let xf = tilted();
    let world = world_of(vec![emitter(disk(0.0, 360.0), xf, false)]);
    let at = |x: f32, y: f32, z: f32| xf.point(Vec3::new(x, y, z));
    li("disk_near", &world, at(0.2, 0.1, 0.5), 14);
    li_far("disk_far", &world, at(0.3, -0.2, 6.0), 15);
    li("disk_grazing", &world, at(1.4, 0.3, 0.25), 16);
    let sector = world_of(vec![emitter(disk(0.4, 270.0), Transform::IDENTITY, false)]);
    li(
        "annulus_sector_near",
        &sector,
        Vec3::new(-0.2, -0.5, 0.6),
        17,
    );
}

#[test]
fn infinite_light_sample_li_follows_pdf_li() {
    let light = Light::Infinite {
        radiance: Rgb::splat(0.7),
        map: None,
    };
    let ctx = LightSampleContext::at_point(Vec3::new(0.3, 2.0, -1.0));
    let scene = test_sphere();
    let report = ChiSquareTest::new("infinite", Domain::Sphere)
        .samples(SAMPLES)
        .seed(18)
        .run_with_pdf(
            |u| {
                let s = light.sample_li(&ctx, u.u2, scene)?;
                assert!(s.at_infinity && !s.delta && s.li == Rgb::splat(0.7));
                Some((s.wi, s.pdf))
            },
            |wi| light.pdf_li(&ctx, wi, None),
        );
    check(&report);
}

fn test_sphere() -> SceneSphere {
    SceneSphere {
        center: Vec3::new(1.0, -2.0, 0.5),
        radius: 3.0,
    }
}

fn assert_close(a: Vec3, b: Vec3, what: &str) {
    assert!(
        (a - b).length() <= 1e-5 * b.length().max(1.0),
        "{what}: {a} vs {b}"
    );
}

/// Delta lights have no density to test: the direction is the one towards the light,
/// the radiance the intensity over the squared distance, and `pdf_li` is zero.
#[test]
fn delta_lights_sample_the_exact_direction() {
    let position = Vec3::new(1.0, 2.0, -0.5);
    let intensity = Rgb::new(3.0, 2.0, 1.0);
    let axis = Vec3::new(0.2, -1.0, 0.1).normalize();
    let point = Light::Point {
        position,
        intensity,
    };
    let spot = Light::Spot {
        position,
        direction: axis,
        intensity,
        cos_falloff_start: 20f32.to_radians().cos(),
        cos_total_width: 30f32.to_radians().cos(),
    };
    let travel = Vec3::new(-0.3, -0.2, -1.0).normalize();
    let distant = Light::Distant {
        direction: travel,
        radiance: intensity,
    };
    let scene = test_sphere();
    let mut rng = Pcg32::new(5, 5);
    for _ in 0..1000 {
        let p = Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 4.0 - Vec3::splat(2.0);
        let ctx = LightSampleContext::at_point(p);
        let u = Vec2::new(rng.uniform(), rng.uniform());
        let to_light = (position - p).normalize();
        let dist2 = (position - p).length_squared();

        let s = point
            .sample_li(&ctx, u, scene)
            .expect("a point light reaches everywhere");
        assert_close(s.wi, to_light, "point light direction");
        assert_close(s.p_light.p, position, "point light position");
        assert!(s.delta && !s.at_infinity && s.pdf == 1.0);
        assert!((s.li.r - intensity.r / dist2).abs() <= 1e-5 * s.li.r);
        assert_eq!(point.pdf_li(&ctx, s.wi, None), 0.0);

        let cos = (-to_light).dot(axis);
        match spot.sample_li(&ctx, u, scene) {
            Some(s) => {
                assert!(
                    cos > 30f32.to_radians().cos() - 1e-6,
                    "lit outside the cone"
                );
                assert_close(s.wi, to_light, "spot light direction");
                let full = intensity.r / dist2;
                if cos >= 20f32.to_radians().cos() {
                    assert!((s.li.r - full).abs() <= 1e-5 * full);
                } else {
                    assert!(s.li.r < full && s.li.r > 0.0);
                }
                assert!(s.delta && s.pdf == 1.0);
            }
            None => assert!(
                cos < 30f32.to_radians().cos() + 1e-6,
                "dark inside the cone"
            ),
        }

        let s = distant
            .sample_li(&ctx, u, scene)
            .expect("a distant light reaches everywhere");
        assert_close(s.wi, -travel, "distant light direction");
        assert!(s.delta && s.at_infinity && s.pdf == 1.0 && s.li == intensity);
        // The shadow ray's end lies outside the scene's sphere, straight towards the light.
        assert!((s.p_light.p - scene.center).length() > scene.radius);
        assert_close(
            (s.p_light.p - p).normalize(),
            -travel,
            "distant light point",
        );
        assert_eq!(distant.pdf_li(&ctx, s.wi, None), 0.0);
    }
}

/// Checks what every emitted sample must satisfy: a unit direction, positive
/// densities, and the closed-form power equal to le |cos| / (pdf_pos pdf_dir).
fn checked(e: LightLeSample) -> LightLeSample {
    let d = e.ray.d;
    assert!((d.length() - 1.0).abs() < 1e-4, "direction {d}");
    assert!(e.pdf_pos > 0.0 && e.pdf_pos.is_finite() && e.pdf_dir.is_finite());
    let cos = if e.n == Vec3::ZERO { 1.0 } else { e.n.dot(d) };
    assert!(cos >= -1e-6, "a ray into the emitting side's back");
    if e.pdf_dir == 0.0 {
        // Cosine sampling's rim (u on the square's edge): a ray along the surface.
        assert!(
            cos.abs() < 1e-6,
            "no density for a direction off the surface"
        );
        return e;
    }
    let power = e.le.g * cos / (e.pdf_pos * e.pdf_dir);
    assert!(
        (power - e.power.g).abs() <= 1e-3 * e.power.g,
        "power {} vs le cos / pdfs {power}",
        e.power.g
    );
    e
}

fn le_test(name: &str, domain: Domain, seed: u64) -> ChiSquareTest {
    ChiSquareTest::new(name, domain).samples(SAMPLES).seed(seed)
}

/// Emission samples against a closed-form density: every claimed density must match.
fn le<P: DomainPoint>(
    test: ChiSquareTest,
    sample: impl FnMut(SampleInput) -> Option<(P, f32)>,
    pdf: impl Fn(P) -> f32,
) {
    run_consistent(test, (1e-3, 0), sample, pdf);
}

const UNIT_SQUARE: Domain = Domain::Rectangle {
    min: Vec2::ZERO,
    max: Vec2::ONE,
};

fn only_light(world: &World) -> &Light {
    assert_eq!(world.lights.len(), 1);
    &world.lights[0]
}

/// `v` moved onto [lo, hi] when within 10⁻⁴ outside (the origin's offset off the
/// surface, round-off); values further out are left to fail the test.
fn snap(v: f32, lo: f32, hi: f32) -> f32 {
    if (lo - 1e-4..=hi + 1e-4).contains(&v) {
        v.clamp(lo, hi)
    } else {
        v
    }
}

/// A point of the plane moved onto the unit disk when just outside it.
fn snap_disk(q: Vec2) -> Vec2 {
    let r2 = q.length_squared();
    if (1.0..1.0 + 1e-4).contains(&r2) {
        q / r2.sqrt()
    } else {
        q
    }
}

/// Directions of rays leaving a surface, in the frame of the normal they claim.
fn le_directions(name: &str, light: &Light, scene: SceneSphere, seed: u64) {
    le(
        le_test(name, Domain::Hemisphere, seed),
        |u| {
            let e = checked(light.sample_le(u.u2, u.u3, scene)?);
            Some((Frame::from_normal(e.n).to_local(e.ray.d), e.pdf_dir))
        },
        |w: Vec3| w.z.max(0.0) * INV_PI,
    );
}

#[test]
fn triangle_light_sample_le_follows_its_densities() {
    let world = world_of(vec![emitter(triangle(), Transform::IDENTITY, false)]);
    let light = only_light(&world);
    let scene = world.scene_sphere();
    // Positions: the barycentrics (b1, b2) of the unit right triangle are the origin's
    // (x, y); x' = b1 + b2, y' = b2 / (b1 + b2) map them onto the unit square with
    // dA = 2 A x' dx' dy', so uniform area has density 2x' there.
    let area = 0.5;
    le(
        le_test("triangle_le_position", UNIT_SQUARE, 19),
        |u| {
            let e = checked(light.sample_le(u.u2, u.u3, scene)?);
            let o = e.ray.o;
            assert!(o.z.abs() < 1e-4);
            let x = snap(o.x + o.y, 0.0, 1.0);
            let y = if x > 0.0 {
                snap(o.y / (o.x + o.y), 0.0, 1.0)
            } else {
                0.0
            };
            Some((Vec2::new(x, y), e.pdf_pos * 2.0 * area * x))
        },
        |p: Vec2| 2.0 * p.x,
    );
    // Directions over the whole sphere: nothing behind a one-sided light.
    le(
        le_test("triangle_le_direction", Domain::Sphere, 20),
        |u| {
            let e = checked(light.sample_le(u.u2, u.u3, scene)?);
            assert_eq!(e.n, Vec3::Z);
            Some((e.ray.d, e.pdf_dir))
        },
        |w: Vec3| w.z.max(0.0) * INV_PI,
    );
    let two_sided = world_of(vec![emitter(triangle(), Transform::IDENTITY, true)]);
    let light = only_light(&two_sided);
    le(
        le_test("triangle_two_sided_le_direction", Domain::Sphere, 21),
        |u| {
            let e = checked(light.sample_le(u.u2, u.u3, scene)?);
            assert_eq!(e.n, Vec3::Z * e.n.z.signum());
            Some((e.ray.d, e.pdf_dir))
        },
        |w: Vec3| 0.5 * w.z.abs() * INV_PI,
    );
}

#[test]
fn bilinear_light_sample_le_follows_its_densities() {
    let world = world_of(vec![emitter(saddle(), Transform::IDENTITY, false)]);
    let light = only_light(&world);
    let Light::Area(area) = light else {
        unreachable!()
    };
    let LightShape::Bilinear { patch, .. } = &area.shape else {
        unreachable!()
    };
    let scene = world.scene_sphere();
    // The patch's (u, v) of a point on it, by Gauss–Newton on p(u, v) = q.
    let uv_of = |q: Vec3| {
        let mut uv = Vec2::splat(0.5);
        for _ in 0..20 {
            let (du, dv) = patch.tangents(uv);
            let r = q - patch.point(uv);
            let (a, b, c) = (du.dot(du), du.dot(dv), dv.dot(dv));
            let det = a * c - b * b;
            let (ru, rv) = (du.dot(r), dv.dot(r));
            uv += Vec2::new(c * ru - b * rv, a * rv - b * ru) / det;
        }
        assert!(
            (patch.point(uv) - q).length() < 1e-3,
            "{q} is off the patch"
        );
        Vec2::new(snap(uv.x, 0.0, 1.0), snap(uv.y, 0.0, 1.0))
    };
    // Positions in (u, v): the density there is pdf_pos times the area element.
    le(
        le_test("bilinear_le_position", UNIT_SQUARE, 22),
        |u| {
            let e = checked(light.sample_le(u.u2, u.u3, scene)?);
            let uv = uv_of(e.ray.o);
            assert!(patch.normal(uv).dot(e.n) > 0.9999, "the front side emits");
            Some((uv, e.pdf_pos * patch.jacobian(uv)))
        },
        |_| 1.0,
    );
    le_directions("bilinear_le_direction", light, scene, 23);
}

#[test]
fn sphere_light_sample_le_follows_its_densities() {
    let centre = Vec3::new(0.5, -0.2, 0.3);
    let radius = 1.5;
    let xf = translate(centre.x, centre.y, centre.z).compose(&scale(radius));
    let world = world_of(vec![emitter(sphere(-1.0, 1.0, 360.0), xf, false)]);
    let light = only_light(&world);
    let scene = world.scene_sphere();
    // Positions as directions from the centre: density pdf_pos r² per solid angle.
    le(
        le_test("sphere_le_position", Domain::Sphere, 24),
        |u| {
            let e = checked(light.sample_le(u.u2, u.u3, scene)?);
            let d = e.ray.o - centre;
            assert!((d.length() - radius).abs() < 1e-4);
            assert!(d.normalize().dot(e.n) > 0.9999, "the outside emits");
            Some((d.normalize(), e.pdf_pos * radius * radius))
        },
        |_| UNIFORM_SPHERE_PDF,
    );
    le_directions("sphere_le_direction", light, scene, 25);
}

#[test]
fn disk_light_sample_le_follows_its_densities() {
    let s = 1.7;
    let xf = tilted().compose(&scale(s));
    let world = world_of(vec![emitter(disk(0.0, 360.0), xf, false)]);
    let light = only_light(&world);
    let scene = world.scene_sphere();
    let object_from_render = xf.inverse();
    let front = xf.normal(Vec3::Z).normalize();
    // Positions in the object's unit disk: density pdf_pos s² (radius 1).
    le(
        le_test("disk_le_position", Domain::Disk, 26),
        |u| {
            let e = checked(light.sample_le(u.u2, u.u3, scene)?);
            let q = object_from_render.point(e.ray.o);
            assert!((q.z - 0.2).abs() < 1e-4, "off the disk's plane: {q}");
            assert!(front.dot(e.n) > 0.9999, "the front side emits");
            Some((snap_disk(q.truncate()), e.pdf_pos * s * s))
        },
        |_| INV_PI,
    );
    le_directions("disk_le_direction", light, scene, 27);
    // An annulus sector: uniform over its part of the unit disk, nothing elsewhere.
    let (inner, phi_max) = (0.4f32, 1.5 * std::f32::consts::PI);
    let sector = world_of(vec![emitter(
        disk(inner, 270.0),
        Transform::IDENTITY,
        false,
    )]);
    let light = only_light(&sector);
    let unit_area = 0.5 * phi_max * (1.0 - inner * inner);
    le(
        le_test("annulus_sector_le_position", Domain::Disk, 28),
        |u| {
            let e = checked(light.sample_le(u.u2, u.u3, scene)?);
            Some((snap_disk(e.ray.o.truncate()), e.pdf_pos))
        },
        |p: Vec2| {
            let phi = p.y.atan2(p.x).rem_euclid(2.0 * std::f32::consts::PI);
            if phi <= phi_max && p.length_squared() >= inner * inner {
                1.0 / unit_area
            } else {
                0.0
            }
        },
    );
}

#[test]
fn point_and_spot_lights_sample_le_follow_their_densities() {
    let scene = test_sphere();
    let position = Vec3::new(0.5, 1.0, -0.2);
    let intensity = Rgb::splat(2.0);
    let point = Light::Point {
        position,
        intensity,
    };
    // Positions are certain: only the directions have a density.
    le(
        le_test("point_le_direction", Domain::Sphere, 29),
        |u| {
            let e = checked(point.sample_le(u.u2, u.u3, scene)?);
            assert_eq!(e.ray.o, position);
            assert_eq!((e.pdf_pos, e.le), (1.0, intensity));
            Some((e.ray.d, e.pdf_dir))
        },
        |_| UNIFORM_SPHERE_PDF,
    );
    let axis = Vec3::new(0.3, -0.8, 0.4).normalize();
    let (cos_start, cos_total) = (25f32.to_radians().cos(), 40f32.to_radians().cos());
    let spot = Light::Spot {
        position,
        direction: axis,
        intensity,
        cos_falloff_start: cos_start,
        cos_total_width: cos_total,
    };
    // Uniform in the whole cone; the falloff is in the radiance.
    le(
        le_test("spot_le_direction", Domain::Sphere, 30),
        |u| {
            let e = checked(spot.sample_le(u.u2, u.u3, scene)?);
            assert_eq!((e.ray.o, e.pdf_pos), (position, 1.0));
            if e.ray.d.dot(axis) >= cos_start {
                assert_eq!(e.le, intensity);
            } else {
                assert!(e.le.g <= intensity.g && e.le.g > 0.0);
            }
            Some((e.ray.d, e.pdf_dir))
        },
        |w: Vec3| {
            if w.dot(axis) > cos_total {
                uniform_cone_pdf(cos_total)
            } else {
                0.0
            }
        },
    );
}

/// Rays of lights at infinity start on the disk of the scene's radius, perpendicular
/// to their direction, one radius before the centre: that disk's unit-disk coordinates.
fn on_scene_disk(e: &LightLeSample, scene: SceneSphere) -> Vec2 {
    let d = e.ray.d;
    let local = Frame::from_normal(d).to_local(e.ray.o - (scene.center - d * scene.radius));
    assert!(
        local.z.abs() < 1e-4 * scene.radius,
        "off the disk's plane: {local}"
    );
    snap_disk(local.truncate() / scene.radius)
}

#[test]
fn lights_at_infinity_sample_le_follow_their_densities() {
    let scene = test_sphere();
    let r2 = scene.radius * scene.radius;
    let travel = Vec3::new(0.4, -0.9, 0.2).normalize();
    let distant = Light::Distant {
        direction: travel,
        radiance: Rgb::splat(1.5),
    };
    // The direction is certain: only the positions have a density.
    le(
        le_test("distant_le_position", Domain::Disk, 31),
        |u| {
            let e = checked(distant.sample_le(u.u2, u.u3, scene)?);
            assert_eq!((e.ray.d, e.pdf_dir), (travel, 1.0));
            Some((on_scene_disk(&e, scene), e.pdf_pos * r2))
        },
        |_| INV_PI,
    );
    let infinite = Light::Infinite {
        radiance: Rgb::splat(0.5),
        map: None,
    };
    le(
        le_test("infinite_le_position", Domain::Disk, 32),
        |u| {
            let e = checked(infinite.sample_le(u.u2, u.u3, scene)?);
            Some((on_scene_disk(&e, scene), e.pdf_pos * r2))
        },
        |_| INV_PI,
    );
    le(
        le_test("infinite_le_direction", Domain::Sphere, 33),
        |u| {
            let e = checked(infinite.sample_le(u.u2, u.u3, scene)?);
            Some((e.ray.d, e.pdf_dir))
        },
        |_| UNIFORM_SPHERE_PDF,
    );
}

/// Direct light on a diffuse floor from lights of every area shape and an environment,
/// three ways: light sampling alone, BSDF sampling alone, and both weighted by the
/// power heuristic with the densities the path tracer uses. MIS weights of the two
/// strategies sum to one for every path only if `pdf_li` at a BSDF-found light is the
/// density light sampling gives that direction; otherwise the weighted estimate is
/// biased. All three must agree within their standard errors.
#[test]
fn mis_weighted_direct_light_has_the_mean_of_each_strategy() {
    let down = rotate(180.0, Vec3::X);
    let floor = {
        let mut s = emitter(
            mesh(
                vec![
                    Vec3::new(-4.0, -4.0, 0.0),
                    Vec3::new(4.0, -4.0, 0.0),
                    Vec3::new(4.0, 4.0, 0.0),
                    Vec3::new(-4.0, 4.0, 0.0),
                ],
                vec![0, 1, 2, 0, 2, 3],
            ),
            Transform::IDENTITY,
            false,
        );
        s.area_light = None;
        s
    };
    let shapes = vec![
        floor,
        emitter(
            planar_quad(),
            translate(-1.0, -0.5, 1.5).compose(&down),
            false,
        ),
        emitter(
            saddle(),
            translate(0.0, -2.0, 2.0)
                .compose(&scale(0.6))
                .compose(&down),
            false,
        ),
        emitter(
            sphere(-1.0, 1.0, 360.0),
            translate(1.2, 0.4, 0.9).compose(&scale(0.3)),
            false,
        ),
        emitter(
            disk(0.0, 360.0),
            translate(-1.2, 1.0, 1.2).compose(&down),
            true,
        ),
    ];
    let lights = vec![LightDesc::Infinite {
        radiance: Rgb::splat(0.3),
        image: None,
        loc: cornell_box().camera.loc,
    }];
    let world = World::build(&scene_of(shapes, lights))
        .expect("the world builds")
        .0;
    let scene = world.scene_sphere();
    let down_ray = Ray::new(Vec3::new(0.2, 0.3, 0.5), -Vec3::Z);
    let hit = world
        .intersect(&down_ray, f32::INFINITY)
        .expect("the floor");
    assert_eq!(hit.light, NO_LIGHT);
    let wo_world = Vec3::Z;
    let material = world.material_at(&hit, wo_world);
    let at = ShadingPoint::new(&hit, material, wo_world);
    let frame = at.frame;
    let ctx = hit.light_sample_context();

    let n = 200_000;
    let mut rng = Pcg32::new(21, 3);
    let mut sums = [[0.0f64; 2]; 3];
    for _ in 0..n {
        let u_choice = rng.uniform();
        let u_light = Vec2::new(rng.uniform(), rng.uniform());
        let ds = direct::sample_direct(&world, scene, &at, u_choice, u_light);
        assert!(ds.shadow_rays <= 1);
        let (light_only, light_weighted) = ds.light.map_or((0.0, 0.0), |d| {
            let c = d.unweighted().g as f64;
            (c, c * power_heuristic(d.light_pdf, d.bsdf_pdf) as f64)
        });

        let u_dir = Vec2::new(rng.uniform(), rng.uniform());
        let (mut bsdf_only, mut bsdf_weighted) = (0.0, 0.0);
        if let Some(bs) = material.sample(at.wo, rng.uniform(), u_dir, TransportMode::Radiance) {
            let wi = frame.to_world(bs.wi);
            let beta = (bs.f * (bs.wi.z.abs() / bs.pdf)).g as f64;
            let (le, pdf_light) = match world.intersect(&hit.spawn_ray(wi), f32::INFINITY) {
                Some(h) if h.light != NO_LIGHT => {
                    let Light::Area(a) = &world.lights[h.light as usize] else {
                        unreachable!()
                    };
                    let pdf = world.light_sampler.pmf(&ctx, h.light as usize)
                        * a.pdf_li(&ctx, &h.light_hit());
                    (a.radiance(h.ng, h.uv, -wi).g, pdf)
                }
                Some(_) => (0.0, 0.0),
                None => pdf_environment(&world, &ctx, wi),
            };
            bsdf_only = beta * le as f64;
            bsdf_weighted = bsdf_only * power_heuristic(bs.pdf, pdf_light) as f64;
        }
        for (sum, v) in sums
            .iter_mut()
            .zip([light_only, bsdf_only, light_weighted + bsdf_weighted])
        {
            sum[0] += v;
            sum[1] += v * v;
        }
    }
    let [light, bsdf, mis] = sums.map(|[s, s2]| {
        let mean = s / n as f64;
        (mean, ((s2 / n as f64 - mean * mean) / n as f64).sqrt())
    });
    println!("light {light:?}, bsdf {bsdf:?}, mis {mis:?}");
    assert!(light.0 > 0.1, "the floor is lit: {light:?}");
    for (name, (mean, se)) in [("BSDF sampling", bsdf), ("MIS", mis)] {
        let bound = 4.0 * (se * se + light.1 * light.1).sqrt();
        assert!(
            (mean - light.0).abs() < bound,
            "{name}: {mean} vs light sampling {} (bound {bound})",
            light.0
        );
    }
}

/// Radiance and light-sampling density of the environment along an escaping ray.
fn pdf_environment(world: &World, ctx: &LightSampleContext, wi: Vec3) -> (f32, f32) {
    let mut le = 0.0;
    let mut pdf = 0.0;
    for (i, light) in world.lights.iter().enumerate() {
        le += light.environment(wi).g;
        pdf += world.light_sampler.pmf(ctx, i) * light.pdf_li(ctx, wi, None);
    }
    (le, pdf)
}
