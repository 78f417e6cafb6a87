//! A light tree: chooses a light for a receiver in proportion to an estimate of how
//! much each light contributes there, by descending a binary tree of light clusters
//! (Conty Estevez & Kulla, "Importance Sampling of Many Lights with Adaptive Tree
//! Splitting", 2018; without the splitting). Each node bounds its lights' positions
//! (a box), their emission directions (a cone of normals plus the spread of emission
//! about a normal) and holds their power; the importance of a node for a receiver is
//! power × a conservative bound on the emitter's cosine / squared distance × a bound on
//! the receiver's cosine. Every light whose contribution can be non-zero keeps a
//! non-zero probability, so estimates stay unbiased; the probability of a given light
//! is recomputed along its root-to-leaf path for multiple importance sampling.
//!
//! Lights at infinity have no position: they are chosen separately, each with the
//! probability of the whole tree.

use glam::Vec3;

use super::area::LightShape;
use super::sampler::SampledLight;
use super::{Light, LightSampleContext, SceneSphere};
use crate::geometry::bounds::Aabb;
use radiant_math::PI;

/// A cone of directions: every direction within `theta` of `axis`.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Cone {
    axis: Vec3,
    /// Half-angle in radians; π: every direction.
    theta: f32,
}

impl Cone {
    const EVERYWHERE: Cone = Cone {
        axis: Vec3::Z,
        theta: PI,
    };

    fn around(axis: Vec3) -> Cone {
        Cone {
            axis: axis.normalize(),
            theta: 0.0,
        }
    }

    /// The smallest cone about a direction between the two axes that holds both.
    fn union(a: Cone, b: Cone) -> Cone {
        if a.theta >= PI || b.theta >= PI {
            return Cone::EVERYWHERE;
        }
        let between = angle_between(a.axis, b.axis);
        if between + b.theta <= a.theta {
            return a;
        }
        if between + a.theta <= b.theta {
            return b;
        }
        let theta = 0.5 * (a.theta + between + b.theta);
        if theta >= PI {
            return Cone::EVERYWHERE;
        }
        let across = a.axis.cross(b.axis);
        if across.length_squared() < 1e-12 {
            // Opposite axes (parallel ones were held above): no one axis between them.
            return Cone::EVERYWHERE;
        }
        // Turn a's axis towards b's until the cone reaches b's far edge.
        let turn = theta - a.theta;
        let axis = glam::Quat::from_axis_angle(across.normalize(), turn) * a.axis;
        Cone {
            axis: axis.normalize(),
            theta,
        }
    }
}

/// Angle between unit vectors, accurate also when they are nearly parallel.
fn angle_between(a: Vec3, b: Vec3) -> f32 {
    if a.dot(b) < 0.0 {
        PI - 2.0 * ((a + b).length() * 0.5).min(1.0).asin()
    } else {
        2.0 * ((b - a).length() * 0.5).min(1.0).asin()
    }
}

/// What a node knows of its lights.
#[derive(Clone, Copy, Debug)]
struct LightBounds {
    bounds: Aabb,
    /// Total power (channel average).
    power: f32,
    /// The lights' front normals (or emission axes).
    normals: Cone,
    /// How far from a normal light still leaves: π/2 for surfaces, 0 for a spot's
    /// cone (held in `normals`).
    theta_e: f32,
    /// Some light emits from both sides: the emitter cosine is taken unsigned.
    two_sided: bool,
}

impl LightBounds {
    fn union(a: &LightBounds, b: &LightBounds) -> LightBounds {
        LightBounds {
            bounds: a.bounds.union(&b.bounds),
            power: a.power + b.power,
            normals: Cone::union(a.normals, b.normals),
            theta_e: a.theta_e.max(b.theta_e),
            two_sided: a.two_sided || b.two_sided,
        }
    }

    /// A conservative estimate of the light this node sends to `ctx`: zero only where
    /// no light of the node can reach the receiver's front or back.
    fn importance(&self, ctx: &LightSampleContext) -> f32 {
        if self.power <= 0.0 {
            return 0.0;
        }
        let (center, radius) = self.bounds.bounding_sphere();
        let to_receiver = ctx.p - center;
        let d2 = to_receiver.length_squared();
        // Inside the bounding sphere every direction is possible.
        let inside = d2 <= radius * radius;
        let theta_b = if inside {
            PI
        } else {
            (radius / d2.sqrt()).min(1.0).asin()
        };
        let d2 = d2.max(radius * radius).max(1e-30);
        let w = if d2 > 0.0 && to_receiver != Vec3::ZERO {
            to_receiver.normalize()
        } else {
            Vec3::Z
        };

        // Emitter side: the angle from the nearest normal of the cone, less the
        // bounding sphere's spread.
        let mut theta_w = angle_between(self.normals.axis, w);
        if self.two_sided {
            theta_w = theta_w.min(PI - theta_w);
        }
        let theta = (theta_w - self.normals.theta - theta_b).max(0.0);
        if theta > self.theta_e {
            return 0.0;
        }
        let cos_emitter = theta.cos().max(0.0);

        // Receiver side: a surface receives from either side (transmission), so the
        // cosine is unsigned, relaxed by the bounding sphere's spread.
        let cos_receiver = if ctx.n == Vec3::ZERO {
            1.0
        } else {
            let theta_i = angle_between(ctx.n.normalize(), -w);
            let theta_i = theta_i.min(PI - theta_i);
            (theta_i - theta_b).max(0.0).cos()
        };
        (self.power * cos_emitter * cos_receiver / d2).max(0.0)
    }
}

/// A node of the tree: a leaf holds one light; an interior node's first child follows
/// it in the node array and `second` is the other.
#[derive(Clone, Copy, Debug)]
struct Node {
    bounds: LightBounds,
    /// Light index (a leaf) or the second child's node index.
    index: u32,
    leaf: bool,
}

/// The tree over a scene's lights with position, and the lights at infinity.
#[derive(Clone, Debug)]
pub struct LightTree {
    nodes: Vec<Node>,
    /// Lights at infinity (distant, environment), chosen uniformly besides the tree.
    infinite: Vec<u32>,
    /// For each light: its path from the root as bits (bit k set: the second child at
    /// depth k) and the path's length; `None` for lights at infinity or without power.
    trails: Vec<Option<(u64, u8)>>,
}

impl LightTree {
    pub fn new(lights: &[Light], scene: SceneSphere) -> LightTree {
        let mut infinite = Vec::new();
        let mut bounded = Vec::new();
        for (i, light) in lights.iter().enumerate() {
            match light_bounds(light, scene) {
                Some(b) if b.power > 0.0 => bounded.push((i as u32, b)),
                Some(_) => {}
                None => infinite.push(i as u32),
            }
        }
        let mut tree = LightTree {
            nodes: Vec::with_capacity(2 * bounded.len()),
            infinite,
            trails: vec![None; lights.len()],
        };
        if !bounded.is_empty() {
            tree.build(&mut bounded, 0, 0);
        }
        tree
    }

    /// Builds the subtree of `lights` (at depth `depth`, reached by `trail`): split in
    /// half at the median of the centroids along their widest axis. Median splits keep
    /// the depth at ⌈log₂ n⌉, well within the 64-bit trail.
    fn build(&mut self, lights: &mut [(u32, LightBounds)], trail: u64, depth: u8) -> LightBounds {
        let at = self.nodes.len();
        if let [(index, bounds)] = lights {
            self.nodes.push(Node {
                bounds: *bounds,
                index: *index,
                leaf: true,
            });
            self.trails[*index as usize] = Some((trail, depth));
            return *bounds;
        }
        let centroids = lights
            .iter()
            .fold(Aabb::default(), |b, (_, l)| b.grow(l.bounds.center()));
        let extent = centroids.diagonal();
        let axis = if extent.x >= extent.y && extent.x >= extent.z {
            0
        } else if extent.y >= extent.z {
            1
        } else {
            2
        };
        let mid = lights.len() / 2;
        lights.select_nth_unstable_by(mid, |a, b| {
            let (ca, cb) = (a.1.bounds.center()[axis], b.1.bounds.center()[axis]);
            ca.total_cmp(&cb).then(a.0.cmp(&b.0))
        });
        // Placeholder until both children are known.
        self.nodes.push(Node {
            bounds: lights[0].1,
            index: 0,
            leaf: false,
        });
        let (first, second) = lights.split_at_mut(mid);
        let a = self.build(first, trail, depth + 1);
        let second_at = self.nodes.len() as u32;
        let b = self.build(second, trail | (1u64 << depth), depth + 1);
        let bounds = LightBounds::union(&a, &b);
        self.nodes[at] = Node {
            bounds,
            index: second_at,
            leaf: false,
        };
        bounds
    }

    /// Probability of choosing the tree rather than one light at infinity.
    fn tree_share(&self) -> f32 {
        if self.nodes.is_empty() {
            0.0
        } else {
            1.0 / (1 + self.infinite.len()) as f32
        }
    }

    /// Picks a light for `ctx` with `u` in [0, 1).
    pub fn sample(&self, ctx: &LightSampleContext, u: f32) -> Option<SampledLight> {
        let tree_share = self.tree_share();
        let infinite_share = 1.0 - tree_share;
        if u < infinite_share {
            let n = self.infinite.len();
            let k = ((u / infinite_share * n as f32) as usize).min(n - 1);
            return Some(SampledLight {
                index: self.infinite[k] as usize,
                pmf: infinite_share / n as f32,
            });
        }
        let mut u = ((u - infinite_share) / tree_share).min(1.0 - f32::EPSILON / 2.0);
        let mut pmf = tree_share;
        let mut node = 0usize;
        if self.nodes.is_empty() || self.nodes[0].bounds.importance(ctx) <= 0.0 {
            return None;
        }
        loop {
            let n = self.nodes[node];
            if n.leaf {
                return Some(SampledLight {
                    index: n.index as usize,
                    pmf,
                });
            }
            let (first, second) = (node + 1, n.index as usize);
            let i0 = self.nodes[first].bounds.importance(ctx);
            let i1 = self.nodes[second].bounds.importance(ctx);
            if i0 + i1 <= 0.0 {
                return None;
            }
            let p0 = i0 / (i0 + i1);
            if u < p0 {
                u = (u / p0).min(1.0 - f32::EPSILON / 2.0);
                pmf *= p0;
                node = first;
            } else {
                u = ((u - p0) / (1.0 - p0)).min(1.0 - f32::EPSILON / 2.0);
                pmf *= 1.0 - p0;
                node = second;
            }
        }
    }

    /// Probability that [`LightTree::sample`] from `ctx` picks light `index`.
    pub fn pmf(&self, ctx: &LightSampleContext, index: usize) -> f32 {
        if self.infinite.contains(&(index as u32)) {
            return (1.0 - self.tree_share()) / self.infinite.len() as f32;
        }
        let Some(Some((trail, depth))) = self.trails.get(index).copied() else {
            return 0.0;
        };
        if self.nodes[0].bounds.importance(ctx) <= 0.0 {
            return 0.0;
        }
        let mut pmf = self.tree_share();
        let mut node = 0usize;
        for level in 0..depth {
            let n = self.nodes[node];
            let (first, second) = (node + 1, n.index as usize);
            let i0 = self.nodes[first].bounds.importance(ctx);
            let i1 = self.nodes[second].bounds.importance(ctx);
            if i0 + i1 <= 0.0 {
                return 0.0;
            }
            // The same arithmetic as `sample`, so both give the same probability.
            let p0 = i0 / (i0 + i1);
            if trail >> level & 1 == 0 {
                pmf *= p0;
                node = first;
            } else {
                pmf *= 1.0 - p0;
                node = second;
            }
        }
        pmf
    }
}

/// Where and how a light emits, `None` for lights at infinity.
fn light_bounds(light: &Light, scene: SceneSphere) -> Option<LightBounds> {
    let power = light.power(scene).average();
    let point = |p: Vec3, normals: Cone, theta_e: f32| LightBounds {
        bounds: Aabb::new(p, p),
        power,
        normals,
        theta_e,
        two_sided: false,
    };
    match light {
        Light::Point { position, .. } => Some(point(*position, Cone::EVERYWHERE, PI / 2.0)),
        Light::Spot {
            position,
            direction,
            cos_total_width,
            ..
        } => Some(point(
            *position,
            Cone {
                axis: direction.normalize(),
                theta: cos_total_width.clamp(-1.0, 1.0).acos(),
            },
            0.0,
        )),
        // Bounded as an isotropic point light, as pbrt-v4 does.
        Light::Goniometric(g) => Some(point(g.position, Cone::EVERYWHERE, PI / 2.0)),
        Light::Projection(pr) => {
            let (axis, cos_width) = pr.cone();
            Some(point(
                pr.position,
                Cone {
                    axis,
                    theta: cos_width.clamp(-1.0, 1.0).acos(),
                },
                0.0,
            ))
        }
        Light::Distant { .. } | Light::Infinite { .. } => None,
        Light::Area(area) => {
            let (bounds, normals) = match &area.shape {
                LightShape::Triangle { p, n, .. } => (Aabb::from_points(p), Cone::around(*n)),
                LightShape::Parallelogram { p, e1, e2, n, .. } => (
                    Aabb::from_points(&[*p, *p + *e1, *p + *e2, *p + *e1 + *e2]),
                    Cone::around(*n),
                ),
                LightShape::Mesh(mesh) => {
                    let bounds = mesh
                        .triangles
                        .iter()
                        .fold(Aabb::default(), |b, t| b.union(&Aabb::from_points(t)));
                    let normals = mesh
                        .normals
                        .iter()
                        .map(|&n| Cone::around(n))
                        .reduce(Cone::union)
                        .unwrap_or(Cone::EVERYWHERE);
                    (bounds, normals)
                }
                LightShape::Sphere {
                    sphere,
                    render_from_object,
                    ..
                } => {
                    let center = render_from_object.point(Vec3::ZERO);
                    let r = sphere.radius * similarity_scale(render_from_object);
                    (
                        Aabb::new(center - Vec3::splat(r), center + Vec3::splat(r)),
                        Cone::EVERYWHERE,
                    )
                }
                LightShape::Disk {
                    disk,
                    render_from_object,
                    normal,
                    ..
                } => {
                    let center = render_from_object.point(Vec3::new(0.0, 0.0, disk.height));
                    let r = disk.radius * similarity_scale(render_from_object);
                    (
                        Aabb::new(center - Vec3::splat(r), center + Vec3::splat(r)),
                        Cone::around(*normal),
                    )
                }
                LightShape::Bilinear { patch, .. } => (
                    Aabb::from_points(&[patch.p00, patch.p10, patch.p01, patch.p11]),
                    // A curved patch's normals are not bounded here.
                    Cone::EVERYWHERE,
                ),
            };
            Some(LightBounds {
                bounds,
                power,
                normals,
                theta_e: PI / 2.0,
                two_sided: area.two_sided,
            })
        }
    }
}

/// Length scale of a similarity transform.
fn similarity_scale(xf: &radiant_math::Transform) -> f32 {
    glam::Mat3::from_mat4(xf.m).determinant().abs().cbrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::{AreaLight, EnvironmentMap, GoniometricLight, ProjectionLight};
    use radiant_math::color::Rgb;
    use radiant_math::hash::Pcg32;

    const SCENE: SceneSphere = SceneSphere {
        center: Vec3::ZERO,
        radius: 10.0,
    };

    fn random_unit(rng: &mut Pcg32) -> Vec3 {
        loop {
            let v = Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 2.0 - Vec3::ONE;
            if v.length_squared() > 1e-3 && v.length_squared() <= 1.0 {
                return v.normalize();
            }
        }
    }

    /// Small triangles scattered in a box, facing anywhere, some two-sided, and a
    /// point and a spot light; plus one light at infinity.
    fn lights(rng: &mut Pcg32, n: usize) -> Vec<Light> {
        let mut lights = Vec::new();
        for i in 0..n {
            let c = Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 8.0 - Vec3::splat(4.0);
            let (a, b) = (random_unit(rng) * 0.3, random_unit(rng) * 0.3);
            let p = [c, c + a, c + b];
            let n = a.cross(b).normalize();
            lights.push(Light::Area(AreaLight {
                shape: LightShape::Triangle {
                    p,
                    n,
                    area: 0.5 * a.cross(b).length(),
                },
                l: Rgb::splat(1.0 + rng.uniform() * 4.0),
                two_sided: i % 5 == 0,
                image: None,
            }));
        }
        lights.push(Light::Point {
            position: Vec3::new(1.0, 2.0, 3.0),
            intensity: Rgb::splat(2.0),
        });
        lights.push(Light::Spot {
            position: Vec3::new(-2.0, 0.0, 1.0),
            direction: Vec3::new(0.0, 0.0, -1.0),
            intensity: Rgb::splat(5.0),
            cos_falloff_start: 0.9,
            cos_total_width: 0.8,
        });
        // Image lights: a projector aimed down-left (bounded by the cone of its image's
        // corners) and a goniometric light.
        let pixels: Vec<Rgb> = (0..6 * 4).map(|k| Rgb::splat(1.0 + k as f32)).collect();
        lights.push(Light::Projection(std::sync::Arc::new(
            ProjectionLight::new(
                Vec3::new(0.5, 1.0, -1.0),
                glam::Mat3::from_rotation_x(2.0) * glam::Mat3::from_rotation_y(0.4),
                40.0,
                6,
                4,
                std::sync::Arc::new(pixels.clone()),
                Rgb::splat(3.0),
            ),
        )));
        let grey: Vec<Rgb> = (0..16).map(|k| Rgb::splat(k as f32 * 0.3)).collect();
        lights.push(Light::Goniometric(std::sync::Arc::new(
            GoniometricLight::new(
                Vec3::new(-1.0, -2.0, 0.5),
                std::sync::Arc::new(EnvironmentMap::new(
                    4,
                    &grey,
                    Rgb::WHITE,
                    glam::Mat3::IDENTITY,
                )),
            ),
        )));
        lights.push(Light::Infinite {
            radiance: Rgb::splat(0.01),
            map: None,
        });
        lights
    }

    fn receiver(rng: &mut Pcg32) -> LightSampleContext {
        let p = Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 10.0 - Vec3::splat(5.0);
        let n = random_unit(rng);
        LightSampleContext {
            p,
            n,
            ns: n,
            mis_with_bsdf: true,
        }
    }

    /// The probabilities `sample` draws lights with are the ones `pmf` states: counts
    /// over a fine stratified u match pmf × n, and each sample's pmf is `pmf`'s.
    #[test]
    fn sampling_frequencies_equal_the_pmf() {
        let mut rng = Pcg32::new(3, 9);
        let lights = lights(&mut rng, 200);
        let tree = LightTree::new(&lights, SCENE);
        for _ in 0..10 {
            let ctx = receiver(&mut rng);
            let n = 100_000;
            let mut counts = vec![0u32; lights.len()];
            for k in 0..n {
                let u = (k as f32 + 0.5) / n as f32;
                if let Some(s) = tree.sample(&ctx, u) {
                    assert_eq!(s.pmf, tree.pmf(&ctx, s.index), "light {}", s.index);
                    counts[s.index] += 1;
                }
            }
            let mut total = 0.0f64;
            for (i, &c) in counts.iter().enumerate() {
                let pmf = tree.pmf(&ctx, i) as f64;
                total += pmf;
                // A stratified u visits each light's interval of width pmf: the count
                // is pmf · n within the rounding of the intervals' ends.
                assert!(
                    (c as f64 - pmf * n as f64).abs() <= 2.0 + 1e-3 * pmf * n as f64,
                    "light {i}: {c} of {n} for pmf {pmf}"
                );
            }
            assert!(total <= 1.0 + 1e-4, "total {total}");
        }
    }

    /// Every light that can light the receiver keeps a non-zero probability: for points
    /// spread over each triangle, where the emitter faces the receiver and the receiver's
    /// surface is not edge-on, the light's pmf is positive.
    #[test]
    fn no_light_that_contributes_is_left_out() {
        let mut rng = Pcg32::new(5, 1);
        let lights = lights(&mut rng, 500);
        let tree = LightTree::new(&lights, SCENE);
        for _ in 0..200 {
            let ctx = receiver(&mut rng);
            for (i, light) in lights.iter().enumerate() {
                let Light::Area(area) = light else {
                    // Point-like lights (a spot or a projector only inside its cone)
                    // and lights at infinity: wherever they shine on the receiver.
                    if light
                        .sample_li(&ctx, glam::Vec2::splat(0.5), SCENE)
                        .is_some()
                    {
                        assert!(tree.pmf(&ctx, i) > 0.0, "light {i}");
                    }
                    continue;
                };
                let LightShape::Triangle { p, n, .. } = area.shape else {
                    unreachable!()
                };
                let contributes = (0..16).any(|k| {
                    let (a, b) = ((k % 4) as f32 / 3.0, (k / 4) as f32 / 3.0);
                    let (a, b) = if a + b > 1.0 {
                        (1.0 - a, 1.0 - b)
                    } else {
                        (a, b)
                    };
                    let q = p[0] + (p[1] - p[0]) * a + (p[2] - p[0]) * b;
                    let w = (ctx.p - q).normalize();
                    let emits = if area.two_sided {
                        n.dot(w) != 0.0
                    } else {
                        n.dot(w) > 0.0
                    };
                    emits && ctx.n.dot(w) != 0.0
                });
                if contributes {
                    assert!(
                        tree.pmf(&ctx, i) > 0.0,
                        "light {i} contributes but has pmf 0"
                    );
                }
            }
        }
    }

    /// Near one cluster of lights, the tree prefers it to a brighter, distant one.
    #[test]
    fn nearby_lights_are_preferred() {
        let tri = |c: Vec3, l: f32| {
            Light::Area(AreaLight {
                shape: LightShape::Triangle {
                    p: [c, c + Vec3::X * 0.1, c + Vec3::Y * 0.1],
                    n: Vec3::Z,
                    area: 0.005,
                },
                l: Rgb::splat(l),
                two_sided: false,
                image: None,
            })
        };
        let lights = [tri(Vec3::ZERO, 1.0), tri(Vec3::new(100.0, 0.0, 0.0), 10.0)];
        let tree = LightTree::new(&lights, SCENE);
        let ctx = LightSampleContext::at_point(Vec3::new(0.0, 0.0, 1.0));
        assert!(tree.pmf(&ctx, 0) > 0.99, "{}", tree.pmf(&ctx, 0));
        // Behind a one-sided emitter nothing is chosen from it.
        let behind = LightSampleContext::at_point(Vec3::new(0.05, 0.02, -1.0));
        assert!(tree.pmf(&behind, 0) < 1e-3, "{}", tree.pmf(&behind, 0));
    }

    #[test]
    fn cone_union_holds_both() {
        let a = Cone::around(Vec3::Z);
        let b = Cone::around(Vec3::X);
        let u = Cone::union(a, b);
        assert!((u.theta - PI / 4.0).abs() < 1e-5);
        assert!(angle_between(u.axis, Vec3::Z) <= u.theta + 1e-5);
        assert!(angle_between(u.axis, Vec3::X) <= u.theta + 1e-5);
        assert_eq!(Cone::union(a, Cone::around(-Vec3::Z)), Cone::EVERYWHERE);
        let wide = Cone {
            axis: Vec3::Z,
            theta: 1.0,
        };
        assert_eq!(
            Cone::union(wide, Cone::around(Vec3::new(0.1, 0.0, 1.0))),
            wide
        );
    }
}
