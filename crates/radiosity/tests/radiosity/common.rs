//! Reading the shared reference data.

use std::ops::ControlFlow;

use radiant_math::DVec3;
use radiant_radiosity::mesh::meshed_scene::RadiosityScene;
use radiant_radiosity::settings::RadiositySettings;
use radiant_radiosity::solve::{Solution, solve};
use radiant_radiosity::{PatchSet, Visibility};
use radiant_render::world::World;
use serde_json::Value;

/// Parses `data/<name>` of the shared data.
pub fn shared_json(name: &str) -> Value {
    let path = radiant_testkit::shared(&format!("data/{name}"));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

pub fn vec3(v: &Value) -> DVec3 {
    DVec3::new(
        v[0].as_f64().unwrap(),
        v[1].as_f64().unwrap(),
        v[2].as_f64().unwrap(),
    )
}

pub fn vertices(v: &Value) -> Vec<DVec3> {
    v.as_array().unwrap().iter().map(vec3).collect()
}

pub fn f64s(v: &Value) -> Vec<f64> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect()
}

pub fn rgb_rows(v: &Value) -> Vec<[f64; 3]> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|row| {
            let r = f64s(row);
            [r[0], r[1], r[2]]
        })
        .collect()
}

pub fn matrix_rows(v: &Value) -> Vec<Vec<f64>> {
    v.as_array().unwrap().iter().map(f64s).collect()
}

/// One case of enclosures.json by name.
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

pub fn max_abs_difference(a: &[[f64; 3]], b: &[[f64; 3]]) -> f64 {
    a.iter()
        .zip(b)
        .flat_map(|(x, y)| (0..3).map(move |k| (x[k] - y[k]).abs()))
        .fold(0.0, f64::max)
}

/// The largest difference between `a` and `b` over all patches and bands, relative to
/// the largest value of `b`.
pub fn max_relative_difference(a: &[[f64; 3]], b: &[[f64; 3]]) -> f64 {
    let scale = b.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    a.iter()
        .zip(b)
        .flat_map(|(x, y)| (0..3).map(move |k| (x[k] - y[k]).abs()))
        .fold(0.0, f64::max)
        / scale
}

/// The solution of `scene` lit by `world`'s lights, solved without interruption.
pub fn solve_to_end<V: Visibility>(
    scene: &RadiosityScene,
    world: &World,
    settings: &RadiositySettings,
    vis: &V,
) -> Solution {
    solve(
        scene,
        &world.lights,
        world.scene_sphere(),
        settings,
        vis,
        |_| ControlFlow::Continue(()),
    )
    .unwrap()
}
