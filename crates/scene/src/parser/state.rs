//! The graphics state that `AttributeBegin` / `AttributeEnd` save and restore: current
//! transform, orientation, material, area light and `Attribute` defaults.

use crate::desc::{LightImage, MaterialId};
use crate::error::FileLoc;
use crate::params::{Param, ParamSet};
use radiant_math::Transform;
use radiant_math::color::Rgb;

/// An `AreaLightSource "diffuse"` waiting for the shapes that follow it.
#[derive(Clone, Debug)]
pub(super) struct AreaLightState {
    /// Radiance as written (`L`; white for an image), before `scale`.
    pub l: Rgb,
    /// `scale` (`power` is applied per shape, since it depends on the shape's area).
    pub scale: Rgb,
    pub two_sided: bool,
    /// `"float power"`: total emitted power in watts, when given (> 0).
    pub power: Option<f32>,
    /// `filename`: emission varying as this picture does.
    pub image: Option<LightImage>,
}

/// Parameters given by `Attribute "<target>" …`, used by later directives of that
/// kind unless they set the parameter themselves.
#[derive(Clone, Debug, Default)]
pub(super) struct AttributeDefaults {
    pub shape: Vec<Param>,
    pub light: Vec<Param>,
    pub material: Vec<Param>,
    pub texture: Vec<Param>,
}

#[derive(Clone, Debug)]
pub(super) struct GraphicsState {
    /// The current transformation matrix: object (or camera) space to world space.
    pub ctm: Transform,
    /// `ActiveTransform`: whether transform directives update the start-time CTM.
    /// radiant renders without motion blur, at the start time only.
    pub start_time_active: bool,
    pub reverse_orientation: bool,
    /// `None` until a `Material` or `NamedMaterial`: pbrt's default diffuse material.
    pub material: Option<MaterialId>,
    pub area_light: Option<AreaLightState>,
    pub defaults: AttributeDefaults,
}

impl Default for GraphicsState {
    fn default() -> Self {
        GraphicsState {
            ctm: Transform::IDENTITY,
            start_time_active: true,
            reverse_orientation: false,
            material: None,
            area_light: None,
            defaults: AttributeDefaults::default(),
        }
    }
}

/// What pushed a saved graphics state, so that the matching end directive pops it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum BlockKind {
    Attribute,
    /// Deprecated `TransformBegin`: restores only the transform.
    Transform,
    Object,
}

impl BlockKind {
    pub fn begin_name(self) -> &'static str {
        match self {
            BlockKind::Attribute => "AttributeBegin",
            BlockKind::Transform => "TransformBegin",
            BlockKind::Object => "ObjectBegin",
        }
    }
}

#[derive(Clone, Debug)]
pub(super) struct SavedState {
    pub state: GraphicsState,
    pub kind: BlockKind,
    pub loc: FileLoc,
}

/// `ps` with the `Attribute` defaults added where it lacks them. The copies are not
/// reported by the directive; a default that no directive reads is reported once, at
/// the end of the scene (see `Parser::report_unused_attributes`).
pub(super) fn with_defaults(mut ps: ParamSet, defaults: &[Param]) -> ParamSet {
    for d in defaults {
        if !ps.has(&d.name) {
            ps.params.push(d.inherited());
        }
    }
    ps
}
