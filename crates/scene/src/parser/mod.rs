//! The pbrt-v4 scene parser: tokens → directives → [`SceneDesc`].
//!
//! Directives are handled by concept: `transforms` (CTM and coordinate systems),
//! `options` (camera, film, sampler, filter, integrator), `blocks` (world, attribute
//! and object blocks, includes), `shapes`, `materials`, `lights`. Semantics follow the
//! pbrt-v4 file-format reference (pbrt.org/fileformat-v4): each transform directive
//! post-multiplies the current transformation matrix (CTM = CTM · T), `Camera` records
//! the CTM as camera-from-world, `WorldBegin` resets the CTM, shapes keep the CTM as
//! render-from-object (render space = world space).
//!
//! Every error names `file:line:column`; everything read but not supported, and every
//! parameter nobody used, becomes a [`Warning`] in [`SceneDesc::warnings`].

mod blocks;
mod lights;
mod materials;
mod options;
mod param_list;
mod shapes;
mod spectrum_param;
mod state;
mod textures;
mod transforms;

use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::Vec2;

use super::desc::*;
use super::error::{FileLoc, SceneError, Warning};
use super::params::{ParamSet, ParamValue};
use super::texture::{ShadingNormalDesc, TextureDesc, TextureId, TextureType};
use super::token::{Lexer, Token, TokenKind};
use radiant_math::Transform;
use state::{GraphicsState, SavedState};

/// Parses a pbrt-v4 scene file (and the files it includes).
pub fn parse_file(path: &Path) -> Result<SceneDesc, SceneError> {
    let text = read_text(path)
        .map_err(|e| e.into_error(|m| SceneError::file(path, format!("cannot read scene: {m}"))))?;
    let base_dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let mut scene = parse_str(&text, &path.display().to_string(), &base_dir)?;
    scene.source = Some(path.to_path_buf());
    Ok(scene)
}

/// Parses several scene files as one: the files are read in order, each continuing the
/// state the previous one left (as pbrt-v4 does with `pbrt a.pbrt b.pbrt`). Relative
/// paths resolve from the writing file's folder, then from the first file's.
pub fn parse_files(paths: &[PathBuf]) -> Result<SceneDesc, SceneError> {
    let Some((first, rest)) = paths.split_first() else {
        return Err(SceneError::file(Path::new("-"), "no scene file given"));
    };
    if rest.is_empty() {
        return parse_file(first);
    }
    let read = |path: &PathBuf| {
        read_text(path).map_err(|e| {
            e.into_error(|m| SceneError::file(path, format!("cannot read scene: {m}")))
        })
    };
    let text = read(first)?;
    let base_dir = first.parent().map(Path::to_path_buf).unwrap_or_default();
    let mut parser = Parser::new(text, &first.display().to_string(), &base_dir);
    // The include stack reads its last entry first: the later files go beneath the
    // first, in reverse, so that each starts where the one before it ends.
    for path in rest.iter().rev() {
        let source = Source {
            lexer: Lexer::new(read(path)?, path.display().to_string()),
            dir: path.parent().map(Path::to_path_buf).unwrap_or_default(),
        };
        parser.sources.insert(0, source);
    }
    parser.run()?;
    let mut scene = parser.finish()?;
    scene.source = Some(first.to_path_buf());
    Ok(scene)
}

/// Parses scene text. `name` is used in locations; relative paths (includes, meshes,
/// lens files) resolve from `base_dir`.
pub fn parse_str(text: &str, name: &str, base_dir: &Path) -> Result<SceneDesc, SceneError> {
    let mut parser = Parser::new(text.to_string(), name, base_dir);
    parser.run()?;
    parser.finish()
}

/// Why a file's text could not be had.
pub(crate) enum ReadError {
    Io(std::io::Error),
    /// Not UTF-8: the location of the first bad byte.
    Encoding(FileLoc),
}

impl ReadError {
    fn into_error(self, io: impl FnOnce(String) -> SceneError) -> SceneError {
        match self {
            ReadError::Io(e) => io(e.to_string()),
            ReadError::Encoding(loc) => SceneError::at(&loc, "file is not valid UTF-8 text"),
        }
    }
}

/// The largest scene or included file read, in bytes. Scenes of that size keep their
/// geometry in PLY files; a larger text is almost surely a wrong path (a device, a log).
pub const MAX_SCENE_FILE_BYTES: u64 = 1 << 30;

/// Reads a text file, reporting the position of invalid UTF-8. Devices (`/dev/zero`)
/// are refused before reading and any file stops at [`MAX_SCENE_FILE_BYTES`]; pipes
/// (`<(...)`) are read up to that limit.
pub(crate) fn read_text(path: &Path) -> Result<String, ReadError> {
    use std::io::Read;
    let too_large = || {
        ReadError::Io(std::io::Error::new(
            std::io::ErrorKind::FileTooLarge,
            format!(
                "larger than the limit of {} MiB for a scene file",
                MAX_SCENE_FILE_BYTES >> 20
            ),
        ))
    };
    let file = std::fs::File::open(path).map_err(ReadError::Io)?;
    let meta = file.metadata().map_err(ReadError::Io)?;
    if meta.is_dir() {
        return Err(ReadError::Io(std::io::Error::new(
            std::io::ErrorKind::IsADirectory,
            "is a folder",
        )));
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        let t = meta.file_type();
        if t.is_char_device() || t.is_block_device() || t.is_socket() {
            return Err(ReadError::Io(std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                "is a device, not a scene file",
            )));
        }
    }
    if meta.len() > MAX_SCENE_FILE_BYTES {
        return Err(too_large());
    }
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    // The limit applies to the text, so a small gzip file cannot expand without bound.
    crate::gz::open_file(file)
        .map_err(ReadError::Io)?
        .take(MAX_SCENE_FILE_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(ReadError::Io)?;
    if bytes.len() as u64 > MAX_SCENE_FILE_BYTES {
        return Err(too_large());
    }
    String::from_utf8(bytes).map_err(|e| {
        let good = &e.as_bytes()[..e.utf8_error().valid_up_to()];
        let line = good.iter().filter(|&&b| b == b'\n').count() as u32 + 1;
        let line_start = good.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1);
        let column = String::from_utf8_lossy(&good[line_start..]).chars().count() as u32 + 1;
        ReadError::Encoding(FileLoc::new(path.display().to_string(), line, column))
    })
}

/// Why a file the scene names (an image, a lens) cannot be read as a file, or `None`
/// when it can: a folder is said to be one rather than reported as missing.
pub(crate) fn not_a_file(path: &Path) -> Option<&'static str> {
    match std::fs::metadata(path) {
        Ok(m) if m.is_dir() => Some("is a directory, not a file"),
        Ok(_) => None,
        Err(_) => Some("not found"),
    }
}

/// One file on the include stack.
struct Source {
    lexer: Lexer,
    /// Folder of the file: relative paths written in it resolve from here first.
    dir: PathBuf,
}

/// Parser state: the token stream, the graphics state and the scene being built.
pub(super) struct Parser {
    sources: Vec<Source>,
    peeked: Option<Token>,
    /// Location of the last token handed out (for "unexpected end of file").
    last_loc: FileLoc,
    /// Folder of the top-level file: the fallback for relative paths, as pbrt-v4
    /// resolves every path from the main scene file's folder.
    top_dir: PathBuf,
    top_name: Arc<str>,

    gs: GraphicsState,
    saved: Vec<SavedState>,
    named_coord_systems: HashMap<String, Transform>,
    named_materials: HashMap<String, MaterialId>,
    default_material: Option<MaterialId>,
    in_world: bool,
    /// The object being defined (`ObjectBegin` … `ObjectEnd`).
    object: Option<ObjectDesc>,
    object_area_light_warned: bool,
    object_index: HashMap<String, usize>,
    /// `ObjectInstance` uses, resolved at the end (pbrt allows forward references).
    instance_uses: Vec<(String, Transform, FileLoc)>,
    notes_given: HashSet<&'static str>,
    /// Every parameter `Attribute` gave, to report those nobody read.
    attribute_params: Vec<blocks::AttributeParam>,

    camera: Option<CameraDesc>,
    film: Option<FilmDesc>,
    sampler: Option<SamplerDesc>,
    filter: Option<FilterDesc>,
    integrator: Option<IntegratorDesc>,
    materials: Vec<MaterialDesc>,
    /// Bump or normal map per material id (see `SceneDesc::shading_normals`).
    shading_normals: Vec<Option<ShadingNormalDesc>>,
    textures: Vec<TextureDesc>,
    /// Texture names per namespace (pbrt-v4 keeps float and spectrum names apart).
    named_textures: HashMap<(TextureType, String), TextureId>,
    shapes: Vec<ShapeDesc>,
    objects: Vec<ObjectDesc>,
    lights: Vec<LightDesc>,
    warnings: Vec<Warning>,
}

/// Deepest include nesting accepted (a file including itself stops here).
const MAX_INCLUDE_DEPTH: usize = 64;

impl Parser {
    fn new(text: String, name: &str, base_dir: &Path) -> Parser {
        let top_name: Arc<str> = name.into();
        Parser {
            sources: vec![Source {
                lexer: Lexer::new(text, top_name.clone()),
                dir: base_dir.to_path_buf(),
            }],
            peeked: None,
            last_loc: FileLoc::new(top_name.clone(), 1, 1),
            top_dir: base_dir.to_path_buf(),
            top_name,
            gs: GraphicsState::default(),
            saved: Vec::new(),
            named_coord_systems: HashMap::new(),
            named_materials: HashMap::new(),
            default_material: None,
            in_world: false,
            object: None,
            object_area_light_warned: false,
            object_index: HashMap::new(),
            instance_uses: Vec::new(),
            notes_given: HashSet::new(),
            attribute_params: Vec::new(),
            camera: None,
            film: None,
            sampler: None,
            filter: None,
            integrator: None,
            materials: Vec::new(),
            shading_normals: Vec::new(),
            textures: Vec::new(),
            named_textures: HashMap::new(),
            shapes: Vec::new(),
            objects: Vec::new(),
            lights: Vec::new(),
            warnings: Vec::new(),
        }
    }

    // ---- tokens ------------------------------------------------------------------

    fn next(&mut self) -> Result<Option<Token>, SceneError> {
        if let Some(t) = self.peeked.take() {
            return Ok(Some(t));
        }
        loop {
            let Some(source) = self.sources.last_mut() else {
                return Ok(None);
            };
            match source.lexer.next_token()? {
                Some(t) => {
                    self.last_loc = t.loc.clone();
                    return Ok(Some(t));
                }
                None => {
                    self.sources.pop();
                }
            }
        }
    }

    fn peek(&mut self) -> Result<Option<&Token>, SceneError> {
        if self.peeked.is_none() {
            self.peeked = self.next()?;
        }
        Ok(self.peeked.as_ref())
    }

    fn unexpected(&self, found: Option<&Token>, expected: &str, directive: &str) -> SceneError {
        match found {
            Some(t) => SceneError::at(
                &t.loc,
                format!(
                    "{directive}: expected {expected}, found {}",
                    t.kind.describe()
                ),
            ),
            None => SceneError::at(
                &self.last_loc,
                format!("{directive}: expected {expected}, found the end of the file"),
            ),
        }
    }

    /// A quoted string argument.
    fn string_arg(&mut self, directive: &str) -> Result<(String, FileLoc), SceneError> {
        match self.next()? {
            Some(Token {
                kind: TokenKind::Str(s),
                loc,
            }) => Ok((s, loc)),
            other => Err(self.unexpected(other.as_ref(), "a quoted string", directive)),
        }
    }

    /// `n` numbers, optionally in brackets (pbrt writes `Transform [ … ]`).
    fn numbers(&mut self, n: usize, directive: &str) -> Result<Vec<f32>, SceneError> {
        let bracketed = matches!(self.peek()?, Some(t) if t.kind == TokenKind::Open);
        if bracketed {
            self.next()?;
        }
        let mut values = Vec::with_capacity(n);
        for _ in 0..n {
            match self.next()? {
                Some(Token {
                    kind: TokenKind::Num { value, .. },
                    loc,
                }) => {
                    let v = value as f32;
                    if !v.is_finite() {
                        return Err(SceneError::at(
                            &loc,
                            format!("{directive}: number is not finite"),
                        ));
                    }
                    values.push(v);
                }
                other => {
                    let what = format!("{n} numbers");
                    return Err(self.unexpected(other.as_ref(), &what, directive));
                }
            }
        }
        if bracketed {
            match self.next()? {
                Some(Token {
                    kind: TokenKind::Close,
                    ..
                }) => {}
                other => return Err(self.unexpected(other.as_ref(), "']'", directive)),
            }
        }
        Ok(values)
    }

    // ---- diagnostics -------------------------------------------------------------

    fn warn(&mut self, loc: &FileLoc, message: impl Into<String>) {
        self.warnings.push(Warning {
            loc: loc.clone(),
            message: message.into(),
        });
    }

    /// A warning given once per scene (for notes that would repeat on every directive).
    fn warn_once(&mut self, key: &'static str, loc: &FileLoc, message: impl Into<String>) {
        if self.notes_given.insert(key) {
            self.warn(loc, message);
        }
    }

    fn report_unused(&mut self, ps: &ParamSet, owner: &str) {
        let unused = ps.unused_warnings(owner);
        self.warnings.extend(unused);
    }

    fn require_world(&self, directive: &str, loc: &FileLoc) -> Result<(), SceneError> {
        if self.in_world {
            Ok(())
        } else {
            Err(SceneError::at(
                loc,
                format!("{directive} is only allowed after WorldBegin"),
            ))
        }
    }

    fn require_options(&self, directive: &str, loc: &FileLoc) -> Result<(), SceneError> {
        if self.in_world {
            Err(SceneError::at(
                loc,
                format!("{directive} is only allowed before WorldBegin"),
            ))
        } else {
            Ok(())
        }
    }

    /// Resolves a path written in the current file: absolute as is; relative from the
    /// current file's folder, else from the main file's folder (pbrt-v4's rule), else
    /// (when neither exists) the first, for the error message.
    fn resolve_path(&self, written: &str) -> PathBuf {
        let p = Path::new(written);
        if p.is_absolute() {
            return p.to_path_buf();
        }
        let here = self
            .sources
            .last()
            .map_or(&self.top_dir, |s| &s.dir)
            .join(p);
        if here.exists() {
            return here;
        }
        let top = self.top_dir.join(p);
        if top.exists() { top } else { here }
    }

    // ---- the directive loop ------------------------------------------------------

    fn run(&mut self) -> Result<(), SceneError> {
        while let Some(token) = self.next()? {
            match token.kind {
                TokenKind::Word(name) => self.directive(&name, &token.loc)?,
                other => {
                    return Err(SceneError::at(
                        &token.loc,
                        format!("expected a directive, found {}", other.describe()),
                    ));
                }
            }
        }
        Ok(())
    }

    fn directive(&mut self, name: &str, loc: &FileLoc) -> Result<(), SceneError> {
        match name {
            "Identity" | "Translate" | "Scale" | "Rotate" | "LookAt" | "Transform"
            | "ConcatTransform" | "CoordinateSystem" | "CoordSysTransform" | "TransformTimes"
            | "ActiveTransform" => self.transform_directive(name, loc),
            "Camera" => self.camera(loc),
            "Film" => self.film(loc),
            "Sampler" => self.sampler(loc),
            "PixelFilter" => self.pixel_filter(loc),
            "Integrator" => self.integrator(loc),
            "Accelerator" => self.accelerator(loc),
            "ColorSpace" => self.color_space(loc),
            "Option" => self.option(loc),
            "WorldBegin" => self.world_begin(loc),
            "WorldEnd" => Ok(()),
            "AttributeBegin" => self.block_begin(state::BlockKind::Attribute, loc),
            "AttributeEnd" => self.block_end(state::BlockKind::Attribute, loc),
            "TransformBegin" => self.block_begin(state::BlockKind::Transform, loc),
            "TransformEnd" => self.block_end(state::BlockKind::Transform, loc),
            "Attribute" => self.attribute(loc),
            "ReverseOrientation" => {
                self.gs.reverse_orientation = !self.gs.reverse_orientation;
                Ok(())
            }
            "Shape" => self.shape(loc),
            "Material" => self.material(loc),
            "MakeNamedMaterial" => self.make_named_material(loc),
            "NamedMaterial" => self.named_material(loc),
            "Texture" => self.texture(loc),
            "LightSource" => self.light_source(loc),
            "AreaLightSource" => self.area_light_source(loc),
            "MakeNamedMedium" => self.make_named_medium(loc),
            "MediumInterface" => self.medium_interface(loc),
            "ObjectBegin" => self.object_begin(loc),
            "ObjectEnd" => self.object_end(loc),
            "ObjectInstance" => self.object_instance(loc),
            "Include" | "Import" => self.include(loc),
            _ => Err(SceneError::at(
                loc,
                format!("unknown directive '{}'", crate::token::excerpt(name)),
            )),
        }
    }

    fn include(&mut self, loc: &FileLoc) -> Result<(), SceneError> {
        let (written, _) = self.string_arg("Include")?;
        if self.sources.len() >= MAX_INCLUDE_DEPTH {
            return Err(SceneError::at(
                loc,
                format!("includes nested deeper than {MAX_INCLUDE_DEPTH} (recursive Include?)"),
            ));
        }
        let path = self.resolve_path(&written);
        let text = read_text(&path).map_err(|e| {
            e.into_error(|m| {
                SceneError::at(
                    loc,
                    format!("cannot read included file '{}': {m}", path.display()),
                )
            })
        })?;
        let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
        // The directive's own parameters are all read; a peeked token belongs to the
        // including file and must come after the included text.
        if let Some(t) = self.peeked.take() {
            return Err(SceneError::at(
                &t.loc,
                format!(
                    "Include: unexpected {} after the file name",
                    t.kind.describe()
                ),
            ));
        }
        self.sources.push(Source {
            lexer: Lexer::new(text, path.display().to_string()),
            dir,
        });
        Ok(())
    }

    // ---- the result --------------------------------------------------------------

    fn default_loc(&self) -> FileLoc {
        FileLoc::new(self.top_name.clone(), 0, 0)
    }

    fn finish(mut self) -> Result<SceneDesc, SceneError> {
        if let Some(open) = self.saved.last() {
            return Err(SceneError::at(
                &open.loc,
                format!("{} without a matching end", open.kind.begin_name()),
            ));
        }
        self.report_unused_attributes();
        let mut instances = Vec::with_capacity(self.instance_uses.len());
        for (name, transform, loc) in std::mem::take(&mut self.instance_uses) {
            let Some(&object) = self.object_index.get(&name) else {
                return Err(SceneError::at(
                    &loc,
                    format!("ObjectInstance of unknown object \"{name}\""),
                ));
            };
            instances.push(InstanceDesc {
                object,
                render_from_instance: transform,
                loc,
            });
        }
        let loc = self.default_loc();
        Ok(SceneDesc {
            camera: self.camera.unwrap_or_else(|| CameraDesc {
                camera_from_world: Transform::IDENTITY,
                kind: CameraKind::Perspective {
                    fov_deg: 90.0,
                    lens_radius: 0.0,
                    focal_distance: 1e6,
                    screen_window: None,
                },
                exposure_time: 1.0,
                loc: loc.clone(),
            }),
            film: self.film.unwrap_or_else(|| FilmDesc {
                xresolution: 1280,
                yresolution: 720,
                filename: Some("pbrt.exr".into()),
                diagonal_mm: 35.0,
                iso: 100.0,
                gbuffer: None,
                max_component_value: f32::INFINITY,
                white_balance: None,
                loc: loc.clone(),
            }),
            sampler: self.sampler.unwrap_or_else(|| SamplerDesc {
                kind: SamplerKind::Sobol,
                pixel_samples: 16,
                seed: 0,
                loc: loc.clone(),
            }),
            filter: self.filter.unwrap_or_else(|| FilterDesc {
                kind: FilterKind::Gaussian { sigma: 0.5 },
                radius: Vec2::splat(1.5),
                loc: loc.clone(),
            }),
            // pbrt-v4's default is "volpath"; without media it is the path tracer, and a
            // default nobody wrote deserves no warning about media.
            integrator: self.integrator.unwrap_or_else(|| IntegratorDesc {
                name: "path".into(),
                params: ParamSet::new().with("maxdepth", ParamValue::Int(vec![5])),
                loc,
            }),
            materials: self.materials,
            shading_normals: self.shading_normals,
            textures: self.textures,
            shapes: self.shapes,
            objects: self.objects,
            instances,
            lights: self.lights,
            warnings: self.warnings,
            source: None,
        })
    }
}
