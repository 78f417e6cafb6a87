//! Structure directives: `WorldBegin`, attribute and transform blocks, `Attribute`
//! defaults, object definitions and instances, and the media directives radiant reads
//! past.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use super::Parser;
use super::state::{BlockKind, SavedState};
use crate::desc::ObjectDesc;
use crate::error::{FileLoc, SceneError};
use crate::token::{Token, TokenKind};
use radiant_math::Transform;

/// A parameter given by `Attribute`, with the flag its copies set when used.
pub(super) struct AttributeParam {
    what: String,
    loc: FileLoc,
    used: Arc<AtomicBool>,
}

impl Parser {
    pub(super) fn world_begin(&mut self, loc: &FileLoc) -> Result<(), SceneError> {
        if self.in_world {
            return Err(SceneError::at(loc, "WorldBegin appears twice"));
        }
        self.in_world = true;
        self.gs.ctm = Transform::IDENTITY;
        self.named_coord_systems
            .insert("world".into(), Transform::IDENTITY);
        Ok(())
    }

    pub(super) fn block_begin(&mut self, kind: BlockKind, loc: &FileLoc) -> Result<(), SceneError> {
        if kind == BlockKind::Transform {
            self.warn_once(
                "transformbegin",
                loc,
                "TransformBegin/TransformEnd are deprecated in pbrt-v4; use AttributeBegin/AttributeEnd",
            );
        }
        self.saved.push(SavedState {
            state: self.gs.clone(),
            kind,
            loc: loc.clone(),
        });
        Ok(())
    }

    pub(super) fn block_end(&mut self, kind: BlockKind, loc: &FileLoc) -> Result<(), SceneError> {
        let end_name = match kind {
            BlockKind::Attribute => "AttributeEnd",
            BlockKind::Transform => "TransformEnd",
            BlockKind::Object => "ObjectEnd",
        };
        let Some(top) = self.saved.last() else {
            return Err(SceneError::at(
                loc,
                format!("{end_name} without a matching {}", kind.begin_name()),
            ));
        };
        if top.kind != kind {
            return Err(SceneError::at(
                loc,
                format!(
                    "{end_name} closes the {} at {}",
                    top.kind.begin_name(),
                    top.loc
                ),
            ));
        }
        let saved = self.saved.pop().expect("checked above");
        if kind == BlockKind::Transform {
            self.gs.ctm = saved.state.ctm;
            self.gs.start_time_active = saved.state.start_time_active;
        } else {
            self.gs = saved.state;
        }
        Ok(())
    }

    /// `Attribute "shape"|"light"|"material"|"texture"|"medium" params`: defaults for
    /// later directives of that kind in the current block (pbrt-v4's five targets).
    /// Each parameter is tracked, so that one no later directive reads is reported.
    pub(super) fn attribute(&mut self, loc: &FileLoc) -> Result<(), SceneError> {
        let (target, at) = self.string_arg("Attribute")?;
        let ps = self.param_list()?;
        let (list, readers) = match target.as_str() {
            "shape" => (&mut self.gs.defaults.shape, "shape"),
            "light" => (&mut self.gs.defaults.light, "light"),
            "material" => (&mut self.gs.defaults.material, "material"),
            "texture" => (&mut self.gs.defaults.texture, "texture"),
            "medium" => {
                ps.mark_all_used();
                self.warn(
                    loc,
                    "Attribute \"medium\": participating media are not supported; ignored",
                );
                return Ok(());
            }
            _ => {
                return Err(SceneError::at(
                    &at,
                    format!(
                        "Attribute: unknown target \"{target}\" (expected \"shape\", \"light\", \"material\", \"medium\" or \"texture\")"
                    ),
                ));
            }
        };
        for mut p in ps.params {
            let used = p.track_uses();
            self.attribute_params.push(AttributeParam {
                what: format!(
                    "parameter \"{} {}\" of Attribute \"{target}\" is not used by any later {readers}",
                    p.value.type_name(),
                    p.name
                ),
                loc: p.loc.clone(),
                used,
            });
            list.retain(|q| q.name != p.name);
            list.push(p);
        }
        Ok(())
    }

    /// Warnings for `Attribute` parameters that no directive read, once each.
    pub(super) fn report_unused_attributes(&mut self) {
        for a in std::mem::take(&mut self.attribute_params) {
            if !a.used.load(Ordering::Relaxed) {
                self.warn(&a.loc, a.what);
            }
        }
    }

    pub(super) fn object_begin(&mut self, loc: &FileLoc) -> Result<(), SceneError> {
        let (name, _) = self.string_arg("ObjectBegin")?;
        self.require_world("ObjectBegin", loc)?;
        if let Some(open) = &self.object {
            return Err(SceneError::at(
                loc,
                format!(
                    "ObjectBegin inside the definition of \"{}\" at {}",
                    open.name, open.loc
                ),
            ));
        }
        if self.object_index.contains_key(&name) {
            return Err(SceneError::at(
                loc,
                format!("object \"{name}\" is defined twice"),
            ));
        }
        self.block_begin(BlockKind::Object, loc)?;
        self.object_area_light_warned = false;
        self.object = Some(ObjectDesc {
            name,
            shapes: Vec::new(),
            loc: loc.clone(),
        });
        Ok(())
    }

    pub(super) fn object_end(&mut self, loc: &FileLoc) -> Result<(), SceneError> {
        if self.object.is_none() {
            return Err(SceneError::at(
                loc,
                "ObjectEnd without a matching ObjectBegin",
            ));
        }
        self.block_end(BlockKind::Object, loc)?;
        let object = self.object.take().expect("checked above");
        self.object_index
            .insert(object.name.clone(), self.objects.len());
        self.objects.push(object);
        Ok(())
    }

    /// `ObjectInstance "name"`: the instance's render-from-instance transform is the
    /// CTM here; the object's shapes keep the CTM of their definition on top.
    pub(super) fn object_instance(&mut self, loc: &FileLoc) -> Result<(), SceneError> {
        let (name, _) = self.string_arg("ObjectInstance")?;
        self.require_world("ObjectInstance", loc)?;
        if self.object.is_some() {
            return Err(SceneError::at(
                loc,
                "ObjectInstance inside an object definition",
            ));
        }
        self.instance_uses.push((name, self.gs.ctm, loc.clone()));
        Ok(())
    }

    pub(super) fn make_named_medium(&mut self, loc: &FileLoc) -> Result<(), SceneError> {
        let (name, _) = self.string_arg("MakeNamedMedium")?;
        self.param_list()?.mark_all_used();
        self.warn(
            loc,
            format!("MakeNamedMedium \"{name}\": participating media are not supported; ignored"),
        );
        Ok(())
    }

    /// `MediumInterface "inside" ["outside"]`: one or two names.
    pub(super) fn medium_interface(&mut self, loc: &FileLoc) -> Result<(), SceneError> {
        let (inside, _) = self.string_arg("MediumInterface")?;
        let mut outside = inside.clone();
        if let Some(Token {
            kind: TokenKind::Str(_),
            ..
        }) = self.peek()?
        {
            outside = self.string_arg("MediumInterface")?.0;
        }
        if !inside.is_empty() || !outside.is_empty() {
            self.warn_once(
                "medium",
                loc,
                "MediumInterface: participating media are not supported; surfaces are rendered in vacuum",
            );
        }
        Ok(())
    }
}
