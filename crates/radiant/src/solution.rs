//! A radiosity solution saved once and displayed by many jobs: `radiant radiosity
//! --save-solution` writes it, `radiant render --integrator radiosity --solution` reads
//! it instead of solving, so a distributed display solves nowhere.
//!
//! The file (`RADSOLN`) holds the scene hash, a hash of the mesh it belongs to (patch
//! areas and reflectances: the meshing settings show there), and per patch the
//! radiosity and irradiance (3 × f64 each), then the ambient term; an FNV-1a checksum
//! closes it. It is written atomically.

use std::io::Write;
use std::path::Path;
use std::time::Instant;

use radiant_image::atomic::atomic_write;
use radiant_radiosity::mesh::meshed_scene::RadiosityScene;
use radiant_radiosity::output::shading::Shading;
use radiant_radiosity::solve::{EscapeContext, PowerBalance, RadiosityStats, Solution};
use radiant_radiosity::{PatchSet, RadiosityIntegrator};
use radiant_render::RenderContext;
use radiant_render::integrator::{Integrator, RenderControl, RenderOutput, Stats, render_passes};

use crate::checkpoint::fnv1a;
use crate::partial::PartialError;

const MAGIC: &[u8; 8] = b"RADSOLN\n";
const VERSION: u32 = 1;

/// A hash of a mesh: what a solution must be displayed on.
pub fn mesh_hash(patches: &PatchSet) -> u64 {
    let mut bytes = Vec::with_capacity(patches.patches.len() * 32);
    for p in &patches.patches {
        bytes.extend_from_slice(&p.area.to_le_bytes());
        for r in p.reflectance {
            bytes.extend_from_slice(&r.to_le_bytes());
        }
    }
    fnv1a(&bytes)
}

/// Writes a solution of `scene` (scene description hash `scene_hash`).
pub fn write(
    path: &Path,
    scene_hash: u64,
    scene: &RadiosityScene,
    solution: &Solution,
) -> Result<(), PartialError> {
    let mut out = Vec::new();
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&VERSION.to_le_bytes());
    out.extend_from_slice(&scene_hash.to_le_bytes());
    out.extend_from_slice(&mesh_hash(&scene.patches).to_le_bytes());
    out.extend_from_slice(&(solution.radiosity.len() as u64).to_le_bytes());
    for v in solution.radiosity.iter().chain(&solution.irradiance) {
        for c in v {
            out.extend_from_slice(&c.to_le_bytes());
        }
    }
    for c in solution.ambient {
        out.extend_from_slice(&c.to_le_bytes());
    }
    out.extend_from_slice(&(solution.iterations as u64).to_le_bytes());
    out.push(solution.converged as u8);
    let sum = fnv1a(&out);
    out.extend_from_slice(&sum.to_le_bytes());
    atomic_write(path, |w| w.write_all(&out))?;
    Ok(())
}

/// Reads a solution and checks it belongs to `scene_hash` and `scene`'s mesh.
pub fn read(
    path: &Path,
    scene_hash: u64,
    scene: &RadiosityScene,
) -> Result<Solution, PartialError> {
    let bytes = std::fs::read(path)?;
    let corrupt = |m: &str| PartialError::Corrupt(format!("{}: {m}", path.display()));
    if bytes.len() < 44 || &bytes[..8] != MAGIC {
        return Err(corrupt(
            "not a radiant radiosity solution (no RADSOLN signature)",
        ));
    }
    let (body, tail) = bytes.split_at(bytes.len() - 8);
    if fnv1a(body).to_le_bytes() != tail {
        return Err(corrupt("the checksum does not match the contents"));
    }
    let mut at = 8;
    let u64_at = |at: &mut usize| -> Result<u64, PartialError> {
        let v = body.get(*at..*at + 8).ok_or_else(|| corrupt("truncated"))?;
        *at += 8;
        Ok(u64::from_le_bytes(v.try_into().expect("8 bytes")))
    };
    let version = u32::from_le_bytes(body[8..12].try_into().expect("4 bytes"));
    at += 4;
    if version != VERSION {
        return Err(corrupt(&format!(
            "format version {version}, this radiant reads {VERSION}"
        )));
    }
    let scene_in = u64_at(&mut at)?;
    if scene_in != scene_hash {
        return Err(PartialError::Mismatch(format!(
            "the solution {} is of another scene (description hash {scene_in:016x}, this one {scene_hash:016x})",
            path.display()
        )));
    }
    let mesh_in = u64_at(&mut at)?;
    let mesh = mesh_hash(&scene.patches);
    let n = u64_at(&mut at)? as usize;
    if mesh_in != mesh || n != scene.patches.patches.len() {
        return Err(PartialError::Mismatch(format!(
            "the solution {} is of another mesh ({n} patches, hash {mesh_in:016x}; this one {} patches, hash {mesh:016x}): mesh with the same settings",
            path.display(),
            scene.patches.patches.len()
        )));
    }
    if body.len() != at + 8 * (6 * n + 3) + 9 {
        return Err(corrupt("wrong length for its patch count"));
    }
    let triple = |at: &mut usize| -> Result<[f64; 3], PartialError> {
        Ok([
            f64::from_bits(u64_at(at)?),
            f64::from_bits(u64_at(at)?),
            f64::from_bits(u64_at(at)?),
        ])
    };
    let radiosity = (0..n)
        .map(|_| triple(&mut at))
        .collect::<Result<Vec<_>, _>>()?;
    let irradiance = (0..n)
        .map(|_| triple(&mut at))
        .collect::<Result<Vec<_>, _>>()?;
    let ambient = triple(&mut at)?;
    let iterations = u64_at(&mut at)? as usize;
    let converged = body[at] != 0;
    Ok(Solution {
        radiosity,
        irradiance,
        ambient,
        balance: PowerBalance::default(),
        iterations,
        converged,
        interrupted: false,
        factor_seconds: 0.0,
        seconds: 0.0,
        closure: Default::default(),
    })
}

/// The radiosity display of a saved solution: renders as [`RadiosityIntegrator`] does
/// after its solve.
pub struct SolvedRadiosity {
    pub radiosity: RadiosityIntegrator,
    pub solution: Solution,
}

impl Integrator for SolvedRadiosity {
    fn name(&self) -> &'static str {
        "radiosity"
    }

    fn render(&self, ctx: &RenderContext, control: &mut RenderControl<'_>) -> RenderOutput {
        let start = Instant::now();
        let scene = &self.radiosity.scene;
        let settings = &self.radiosity.settings;
        let display = self.solution.display_radiosity(&scene.patches);
        let shading = Shading::new(
            scene,
            &ctx.world,
            &display,
            &self.solution.irradiance,
            settings.final_gather,
        )
        .with_specular_depth(settings.max_depth);
        let mut out = render_passes(ctx, &shading, control);
        out.seconds = start.elapsed().as_secs_f64();
        out.stats = Stats::new(RadiosityStats {
            patches: scene.patches.len(),
            escape: EscapeContext::of(settings, &ctx.world.lights),
            iterations: self.solution.iterations,
            converged: self.solution.converged,
            solve_seconds: 0.0,
            balance: self.solution.balance,
        });
        out
    }
}
