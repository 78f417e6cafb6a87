//! `Integrator "radiosity"`: its parameters, each documented where it is read.
//!
//! ```text
//! Integrator "radiosity"
//!     "float maxpatcharea" [600]        # scene units^2 (default: total area / 2000)
//!     "integer subdivision" [1]         # split every input edge into at least this many
//!     "string formfactor" "raycast"     # or "hemicube"
//!     "integer hemicuberes" [128]
//!     "string solver" "progressive"     # or "gaussseidel", "jacobi"
//!     "float tolerance" [0.001]
//!     "integer maxiterations" [100000]
//!     "integer finalgather" [0]         # gather rays per camera sample (0: Gouraud display)
//!     "string visibility" "patches"     # or "world"
//!     "bool twosided" [true; false for the built-in scenes]
//!     "integer maxdepth" [8]            # specular bounces of camera rays (display)
//!     "integer refine" [0]              # adaptive refinement passes (0: none)
//!     "float refinethreshold" [0.1]     # neighbour contrast that splits patches
//!     "integer contactgrading" [0]      # a-priori rows halving towards contact edges
//! ```

use radiant_scene::{IntegratorDesc, SceneDesc, SceneError};

/// Where the form factors come from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FormFactorMethod {
    /// Exact point-to-polygon contour factors with shadow rays through the BVH.
    RayCast,
    /// Cohen & Greenberg's hemi-cube with its own depth buffer.
    HemiCube,
}

/// How the linear system is solved.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SolverKind {
    /// Progressive refinement (shooting), O(N) memory, factors on the fly.
    Progressive,
    /// Full factor matrix, then Gauss-Seidel sweeps.
    GaussSeidel,
    /// Full factor matrix, then Jacobi sweeps (parallel).
    Jacobi,
}

/// Which geometry answers shadow rays while the factors are computed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VisibilitySource {
    /// A triangle BVH over the unsubdivided diffuse faces the patches come from (the
    /// same surfaces the solver sees, tessellated spheres included).
    Patches,
    /// The renderer's world (analytic spheres and disks, instances).
    World,
}

/// Settings of the radiosity integrator.
#[derive(Clone, Debug, PartialEq)]
pub struct RadiositySettings {
    /// Largest patch area in scene units squared; `None` picks the total diffuse
    /// area / [`DEFAULT_PATCH_COUNT`] (which gives somewhat more patches, as edges
    /// are split into whole numbers of segments).
    pub max_patch_area: Option<f64>,
    /// Every input edge is split into at least this many segments.
    pub subdivision: u32,
    pub form_factor: FormFactorMethod,
    pub hemicube_resolution: usize,
    pub solver: SolverKind,
    /// Progressive: stop at this fraction of the emitted power left unshot. Matrix
    /// solvers: stop when a sweep changes no radiosity by more than this fraction of
    /// the largest.
    pub tolerance: f64,
    /// Shots (progressive) or sweeps (matrix solvers) at most.
    pub max_iterations: usize,
    /// Gather rays per camera sample; 0 shows the interpolated radiosity directly.
    pub final_gather: u32,
    pub visibility: VisibilitySource,
    /// Also mesh the back side of every non-emitting diffuse surface.
    pub two_sided: bool,
    /// Specular bounces a camera ray follows (mirrors, glass) before it gives up.
    pub max_depth: u32,
    /// Adaptive refinement passes: solve, split the patches whose radiosity differs
    /// from a neighbour's by more than `refine_threshold`, solve again (see
    /// [`crate::solve::adaptive`]). 0 solves the first mesh only.
    pub refine: u32,
    /// Relative radiosity contrast between neighbouring patches of one surface above
    /// which both are split.
    pub refine_threshold: f64,
    /// Levels of a-priori grading towards contact edges (a block on the floor): the
    /// elements touching one are split this many times over (see [`crate::mesh::contact_grading`]).
    pub contact_grading: u32,
}

/// Patches aimed at when no `maxpatcharea` is given.
pub const DEFAULT_PATCH_COUNT: f64 = 2000.0;

impl Default for RadiositySettings {
    fn default() -> Self {
        RadiositySettings {
            max_patch_area: None,
            subdivision: 1,
            form_factor: FormFactorMethod::RayCast,
            hemicube_resolution: 128,
            solver: SolverKind::Progressive,
            tolerance: 1e-3,
            max_iterations: 100_000,
            final_gather: 0,
            visibility: VisibilitySource::Patches,
            two_sided: false,
            max_depth: 8,
            refine: 0,
            refine_threshold: 0.1,
            contact_grading: 0,
        }
    }
}

impl RadiositySettings {
    /// Reads `desc`, the parameters of `Integrator "radiosity"` for `scene`, with the
    /// defaults of the scene's origin: a scene read from a pbrt file is two-sided
    /// unless it says otherwise, as pbrt's diffuse BSDFs reflect on both sides and such
    /// scenes do not wind their faces towards the light (Bitterli's Cornell box faces
    /// outwards, and one-sided patches left it black with 88 % of the light escaping);
    /// the built-in scenes keep one-sided patches, wound towards the inside.
    pub fn for_scene(
        desc: &IntegratorDesc,
        scene: &SceneDesc,
    ) -> Result<RadiositySettings, SceneError> {
        let builtin = scene.camera.loc.file.starts_with("<builtin:");
        Self::read(desc, !builtin)
    }

    /// Reads the parameters of `Integrator "radiosity"` with the built-in scenes'
    /// defaults (one-sided); errors name the file and line.
    pub fn from_desc(desc: &IntegratorDesc) -> Result<RadiositySettings, SceneError> {
        Self::read(desc, false)
    }

    fn read(
        desc: &IntegratorDesc,
        two_sided_default: bool,
    ) -> Result<RadiositySettings, SceneError> {
        let params = &desc.params;
        let defaults = RadiositySettings::default();
        let bad = |name: &str, message: String| {
            let loc = params.lookup(name).map_or(&desc.loc, |p| &p.loc).clone();
            SceneError::at(
                &loc,
                format!("Integrator \"radiosity\": \"{name}\" {message}"),
            )
        };
        // "float maxpatcharea" [total diffuse area / 2000]: largest patch area, scene
        // units^2. Example: `"float maxpatcharea" [230]` gives 10^4 patches in the
        // Cornell box (mm).
        let max_patch_area = if params.has("maxpatcharea") {
            let a = params.finite_float("maxpatcharea", 0.0)?;
            if a <= 0.0 {
                return Err(bad("maxpatcharea", format!("must be positive, got {a}")));
            }
            Some(a as f64)
        } else {
            None
        };
        // "integer subdivision" [1]: split every input edge into at least this many
        // segments (a quad into n x n patches), whatever its size.
        // Example: `"integer subdivision" [8]`.
        let subdivision = params.count("subdivision", defaults.subdivision)?;
        if subdivision == 0 || subdivision > 4096 {
            return Err(bad(
                "subdivision",
                format!("must lie in 1..=4096, got {subdivision}"),
            ));
        }
        // "string formfactor" ["raycast"]: "raycast" (exact contour factors with shadow
        // rays) or "hemicube". Example: `"string formfactor" "hemicube"`.
        let form_factor = match params.string("formfactor", "raycast".into())?.as_str() {
            "raycast" => FormFactorMethod::RayCast,
            "hemicube" => FormFactorMethod::HemiCube,
            other => {
                return Err(bad(
                    "formfactor",
                    format!("must be \"raycast\" or \"hemicube\", got \"{other}\""),
                ));
            }
        };
        // "integer hemicuberes" [128]: cells across the hemi-cube's top face (even).
        // Example: `"integer hemicuberes" [256]`.
        let hemicube_resolution = params.count("hemicuberes", 128)? as usize;
        if hemicube_resolution < 2
            || !hemicube_resolution.is_multiple_of(2)
            || hemicube_resolution > 4096
        {
            return Err(bad(
                "hemicuberes",
                format!("must be even and in 2..=4096, got {hemicube_resolution}"),
            ));
        }
        // "string solver" ["progressive"]: "progressive" (shooting), "gaussseidel" or
        // "jacobi" (both on the full factor matrix, N^2 memory).
        // Example: `"string solver" "gaussseidel"`.
        let solver = match params.string("solver", "progressive".into())?.as_str() {
            "progressive" => SolverKind::Progressive,
            "gaussseidel" => SolverKind::GaussSeidel,
            "jacobi" => SolverKind::Jacobi,
            other => {
                return Err(bad(
                    "solver",
                    format!(
                        "must be \"progressive\", \"gaussseidel\" or \"jacobi\", got \"{other}\""
                    ),
                ));
            }
        };
        // "float tolerance" [0.001]: progressive: unshot power / emitted power at which
        // to stop; matrix solvers: largest change in a sweep / largest radiosity.
        // Example: `"float tolerance" [0.01]`.
        let tolerance = params.finite_float("tolerance", defaults.tolerance as f32)? as f64;
        if !(tolerance > 0.0 && tolerance < 1.0) {
            return Err(bad(
                "tolerance",
                format!("must lie in (0, 1), got {tolerance}"),
            ));
        }
        // "integer maxiterations" [100000]: shots (progressive) or sweeps at most.
        // Example: `"integer maxiterations" [5000]`.
        let max_iterations =
            params.count("maxiterations", defaults.max_iterations as u32)? as usize;
        if max_iterations == 0 {
            return Err(bad("maxiterations", "must be at least 1".into()));
        }
        // "integer finalgather" [0]: rays per camera sample gathering the solved
        // radiosity one bounce away (direct light by light sampling); 0 shows the
        // Gouraud-interpolated radiosity. Example: `"integer finalgather" [16]`.
        let final_gather = params.count("finalgather", 0)?;
        // "string visibility" ["patches"]: shadow rays against the faces the patches
        // come from ("patches") or against the render world ("world").
        // Example: `"string visibility" "world"`.
        let visibility = match params.string("visibility", "patches".into())?.as_str() {
            "patches" => VisibilitySource::Patches,
            "world" => VisibilitySource::World,
            other => {
                return Err(bad(
                    "visibility",
                    format!("must be \"patches\" or \"world\", got \"{other}\""),
                ));
            }
        };
        // "bool twosided" [true for scenes read from pbrt files, false for the built-in
        // ones]: false makes patches one-sided (front = the side the shape's normal
        // points to); true adds a back patch to every non-emitting diffuse face.
        // Example: `"bool twosided" false`.
        let two_sided = params.bool("twosided", two_sided_default)?;
        // "integer maxdepth" [8]: specular bounces (mirror, glass) a camera ray follows
        // to the diffuse surface it shows; the solve itself is diffuse only.
        // Example: `"integer maxdepth" [16]`.
        let max_depth = params.count("maxdepth", defaults.max_depth)?;
        // "integer refine" [0]: adaptive refinement passes. Each solves the current
        // mesh, splits the patches whose radiosity differs from a neighbour's on the
        // same surface by more than "refinethreshold" (shadow boundaries, contact
        // shadows) and their neighbours as far as the mesh must stay conforming, then
        // solves again. Example: `"integer refine" [3]`.
        let refine = params.count("refine", defaults.refine)?;
        if refine > 12 {
            return Err(bad("refine", format!("must lie in 0..=12, got {refine}")));
        }
        // "float refinethreshold" [0.1]: the relative contrast |B_i - B_k| / max(B_i,
        // B_k) (largest over the bands) between neighbours that splits both.
        // Example: `"float refinethreshold" [0.05]`.
        let refine_threshold =
            params.finite_float("refinethreshold", defaults.refine_threshold as f32)? as f64;
        if refine_threshold <= 0.0 {
            return Err(bad(
                "refinethreshold",
                format!("must be positive, got {refine_threshold}"),
            ));
        }
        // "integer contactgrading" [0]: before the first solve, split the elements that
        // touch a contact edge (where a surface rests on another it shares no edge
        // with, such as a block on the floor) this many times over, so rows of
        // elements halve towards the contact line. Example: `"integer contactgrading" [3]`.
        let contact_grading = params.count("contactgrading", defaults.contact_grading)?;
        if contact_grading > 12 {
            return Err(bad(
                "contactgrading",
                format!("must lie in 0..=12, got {contact_grading}"),
            ));
        }
        Ok(RadiositySettings {
            max_patch_area,
            subdivision,
            form_factor,
            hemicube_resolution,
            solver,
            tolerance,
            max_iterations,
            final_gather,
            visibility,
            two_sided,
            max_depth,
            refine,
            refine_threshold,
            contact_grading,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use radiant_scene::{FileLoc, ParamSet, ParamValue};

    fn desc(params: ParamSet) -> IntegratorDesc {
        IntegratorDesc {
            name: "radiosity".into(),
            params,
            loc: FileLoc::new("scene.pbrt", 3, 1),
        }
    }

    #[test]
    fn pbrt_scenes_default_to_two_sided_patches_and_built_in_ones_do_not() {
        let builtin = radiant_scene::builtin::cornell_box();
        let plain = desc(ParamSet::new());
        assert!(
            !RadiositySettings::for_scene(&plain, &builtin)
                .unwrap()
                .two_sided
        );
        let mut from_file = builtin.clone();
        from_file.camera.loc = FileLoc::new("scene.pbrt", 2, 1);
        assert!(
            RadiositySettings::for_scene(&plain, &from_file)
                .unwrap()
                .two_sided
        );
        let one_sided = desc(ParamSet::new().with("twosided", ParamValue::Bool(vec![false])));
        assert!(
            !RadiositySettings::for_scene(&one_sided, &from_file)
                .unwrap()
                .two_sided
        );
    }

    #[test]
    fn parameters_are_read_and_checked() {
        let s = RadiositySettings::from_desc(&desc(
            ParamSet::new()
                .with("maxpatcharea", ParamValue::Float(vec![200.0]))
                .with("formfactor", ParamValue::String(vec!["hemicube".into()]))
                .with("solver", ParamValue::String(vec!["jacobi".into()]))
                .with("finalgather", ParamValue::Int(vec![8])),
        ))
        .unwrap();
        assert_eq!(s.max_patch_area, Some(200.0));
        assert_eq!(s.form_factor, FormFactorMethod::HemiCube);
        assert_eq!(s.solver, SolverKind::Jacobi);
        assert_eq!(s.final_gather, 8);
        let e = RadiositySettings::from_desc(&desc(
            ParamSet::new().with("solver", ParamValue::String(vec!["magic".into()])),
        ))
        .unwrap_err()
        .to_string();
        assert!(e.contains("solver") && e.contains("magic"), "{e}");
        assert!(
            RadiositySettings::from_desc(&desc(
                ParamSet::new().with("hemicuberes", ParamValue::Int(vec![63]))
            ))
            .is_err()
        );
    }
}
