//! Parameter lists: `"type name" value` or `"type name" [ values ]`, repeated.

use glam::{Vec2, Vec3};

use super::Parser;
use crate::error::{FileLoc, SceneError};
use crate::params::{Param, ParamSet, ParamValue};
use crate::token::{Token, TokenKind};
use radiant_math::color::Rgb;

/// The values of one parameter as written, before they are typed.
enum RawValues {
    /// The numbers, and the first that is not a 32-bit integer literal (kept apart
    /// so that large meshes cost 8 bytes per number while they are read).
    Numbers {
        values: Vec<f64>,
        first_non_int: Option<NonInt>,
    },
    Strings(Vec<(String, FileLoc)>),
    Bools(Vec<bool>),
}

/// A number that cannot be an `integer` value: its value, where it is, and its
/// integer literal when it was written as one (then too large for 32 bits).
type NonInt = (f64, FileLoc, Option<i64>);

/// pbrt type names (v3 spellings included) to the canonical ones.
fn canonical_type(t: &str) -> Option<&'static str> {
    Some(match t {
        "integer" => "integer",
        "float" => "float",
        "bool" => "bool",
        "string" => "string",
        "point2" => "point2",
        "vector2" => "vector2",
        "point3" | "point" => "point3",
        "vector3" | "vector" => "vector3",
        "normal3" | "normal" => "normal",
        "rgb" | "color" => "rgb",
        "spectrum" => "spectrum",
        "blackbody" => "blackbody",
        "texture" => "texture",
        _ => return None,
    })
}

impl Parser {
    /// Reads parameters while the next token is a quoted string.
    pub(super) fn param_list(&mut self) -> Result<ParamSet, SceneError> {
        let mut ps = ParamSet::new();
        while let Some(Token {
            kind: TokenKind::Str(_),
            ..
        }) = self.peek()?
        {
            let Some(Token {
                kind: TokenKind::Str(decl),
                loc,
            }) = self.next()?
            else {
                unreachable!("peeked a string");
            };
            let p = self.param(&decl, loc)?;
            if ps.has(&p.name) {
                return Err(SceneError::at(
                    &p.loc,
                    format!("parameter \"{}\" is given twice", p.name),
                ));
            }
            ps.params.push(p);
        }
        Ok(ps)
    }

    fn param(&mut self, decl: &str, loc: FileLoc) -> Result<Param, SceneError> {
        let words: Vec<&str> = decl.split_whitespace().collect();
        let [ty, name] = words[..] else {
            return Err(SceneError::at(
                &loc,
                format!("bad parameter declaration \"{decl}\": expected \"type name\""),
            ));
        };
        let Some(ty) = canonical_type(ty) else {
            return Err(SceneError::at(
                &loc,
                format!("unknown parameter type \"{ty}\""),
            ));
        };
        let raw = self.raw_values(name)?;
        let value = typed_value(ty, name, raw, &loc)?;
        Ok(Param::new(name, value, loc))
    }

    /// One value, or a bracketed list of values of one kind (numbers, strings, bools).
    fn raw_values(&mut self, name: &str) -> Result<RawValues, SceneError> {
        let what = format!("parameter \"{name}\"");
        let bracketed = matches!(self.peek()?, Some(t) if t.kind == TokenKind::Open);
        if bracketed {
            self.next()?;
        }
        let mut raw: Option<RawValues> = None;
        loop {
            let token = self.next()?;
            let Some(Token { kind, loc }) = token else {
                return Err(self.unexpected(None, "a value", &what));
            };
            let mismatch = |loc: &FileLoc| {
                SceneError::at(
                    loc,
                    format!("{what}: values of different kinds in one list"),
                )
            };
            match kind {
                TokenKind::Close if bracketed => break,
                TokenKind::Num { value, integer } => match raw.get_or_insert(RawValues::Numbers {
                    values: Vec::new(),
                    first_non_int: None,
                }) {
                    RawValues::Numbers {
                        values,
                        first_non_int,
                    } => {
                        let is_i32 = integer.is_some_and(|i| i32::try_from(i).is_ok());
                        if !is_i32 && first_non_int.is_none() {
                            *first_non_int = Some((value, loc, integer));
                        }
                        values.push(value);
                    }
                    _ => return Err(mismatch(&loc)),
                },
                TokenKind::Str(s) => match raw.get_or_insert(RawValues::Strings(Vec::new())) {
                    RawValues::Strings(v) => v.push((s, loc)),
                    _ => return Err(mismatch(&loc)),
                },
                TokenKind::Word(w) if w == "true" || w == "false" => {
                    match raw.get_or_insert(RawValues::Bools(Vec::new())) {
                        RawValues::Bools(v) => v.push(w == "true"),
                        _ => return Err(mismatch(&loc)),
                    }
                }
                other => {
                    let t = Token { kind: other, loc };
                    return Err(self.unexpected(Some(&t), "a value", &what));
                }
            }
            if !bracketed {
                break;
            }
        }
        Ok(raw.unwrap_or(RawValues::Numbers {
            values: Vec::new(),
            first_non_int: None,
        }))
    }
}

fn floats(raw: RawValues, ty: &str, name: &str, loc: &FileLoc) -> Result<Vec<f32>, SceneError> {
    match raw {
        RawValues::Numbers { values, .. } => Ok(values.into_iter().map(|x| x as f32).collect()),
        _ => Err(SceneError::at(
            loc,
            format!("parameter \"{ty} {name}\" needs numbers"),
        )),
    }
}

fn grouped<const N: usize, T>(
    values: Vec<f32>,
    ty: &str,
    name: &str,
    loc: &FileLoc,
    make: impl Fn(&[f32]) -> T,
) -> Result<Vec<T>, SceneError> {
    if !values.len().is_multiple_of(N) {
        return Err(SceneError::at(
            loc,
            format!(
                "parameter \"{ty} {name}\" needs a multiple of {N} numbers, found {}",
                values.len()
            ),
        ));
    }
    Ok(values.chunks_exact(N).map(make).collect())
}

fn typed_value(
    ty: &str,
    name: &str,
    raw: RawValues,
    loc: &FileLoc,
) -> Result<ParamValue, SceneError> {
    let need = |kind: &str| SceneError::at(loc, format!("parameter \"{ty} {name}\" needs {kind}"));
    Ok(match ty {
        "integer" => match raw {
            RawValues::Numbers {
                first_non_int: Some((x, at, literal)),
                ..
            } => {
                let why = match literal {
                    Some(i) => format!("{i} does not fit a 32-bit integer"),
                    None if x.fract() != 0.0 || !x.is_finite() => {
                        format!("{x} is not an integer")
                    }
                    // 1e1 or 10.0: an integer value, but not written as one (pbrt-v4
                    // refuses it too).
                    None => "an integer must be written without a fraction or exponent".to_string(),
                };
                return Err(SceneError::at(
                    &at,
                    format!("parameter \"integer {name}\": {why}"),
                ));
            }
            // Every value is an integer literal within i32, so the f64 holds it exactly.
            RawValues::Numbers { values, .. } => {
                ParamValue::Int(values.into_iter().map(|x| x as i32).collect())
            }
            _ => return Err(need("integers")),
        },
        "bool" => match raw {
            RawValues::Bools(v) => ParamValue::Bool(v),
            RawValues::Strings(v) => ParamValue::Bool(
                v.into_iter()
                    .map(|(s, at)| match s.as_str() {
                        "true" => Ok(true),
                        "false" => Ok(false),
                        _ => Err(SceneError::at(
                            &at,
                            format!("parameter \"{name}\": \"{s}\" is not a bool"),
                        )),
                    })
                    .collect::<Result<_, _>>()?,
            ),
            RawValues::Numbers { .. } => return Err(need("true or false")),
        },
        "string" | "texture" => match raw {
            RawValues::Strings(v) => {
                let s: Vec<String> = v.into_iter().map(|(s, _)| s).collect();
                if ty == "string" {
                    ParamValue::String(s)
                } else {
                    ParamValue::Texture(s)
                }
            }
            _ => return Err(need("quoted strings")),
        },
        "spectrum" => match raw {
            RawValues::Strings(v) => {
                ParamValue::SpectrumNamed(v.into_iter().map(|(s, _)| s).collect())
            }
            RawValues::Numbers { .. } => ParamValue::SpectrumSamples(floats(raw, ty, name, loc)?),
            RawValues::Bools(_) => return Err(need("numbers or a spectrum name")),
        },
        "float" => ParamValue::Float(floats(raw, ty, name, loc)?),
        "blackbody" => ParamValue::Blackbody(floats(raw, ty, name, loc)?),
        "point2" => ParamValue::Point2(grouped::<2, _>(
            floats(raw, ty, name, loc)?,
            ty,
            name,
            loc,
            Vec2::from_slice,
        )?),
        "vector2" => ParamValue::Vector2(grouped::<2, _>(
            floats(raw, ty, name, loc)?,
            ty,
            name,
            loc,
            Vec2::from_slice,
        )?),
        "point3" => ParamValue::Point3(grouped::<3, _>(
            floats(raw, ty, name, loc)?,
            ty,
            name,
            loc,
            Vec3::from_slice,
        )?),
        "vector3" => ParamValue::Vector3(grouped::<3, _>(
            floats(raw, ty, name, loc)?,
            ty,
            name,
            loc,
            Vec3::from_slice,
        )?),
        "normal" => ParamValue::Normal3(grouped::<3, _>(
            floats(raw, ty, name, loc)?,
            ty,
            name,
            loc,
            Vec3::from_slice,
        )?),
        "rgb" => ParamValue::Rgb(grouped::<3, _>(
            floats(raw, ty, name, loc)?,
            ty,
            name,
            loc,
            |c| Rgb::new(c[0], c[1], c[2]),
        )?),
        _ => unreachable!("canonical_type returns only the names above"),
    })
}
