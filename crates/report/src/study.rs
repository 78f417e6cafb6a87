//! The plain data a report is made of: what `radiant study` measured for each method.
//!
//! Nothing here computes metrics; the numbers are shown exactly as given, so a report
//! always agrees with the tool that made it.

/// A linear-RGB image, row-major from the top-left pixel.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ReportImage {
    pub width: usize,
    pub height: usize,
    /// `width * height` linear RGB values; HDR values above 1 are kept as they are.
    pub pixels: Vec<[f32; 3]>,
}

impl ReportImage {
    /// An image of `width × height` pixels, all `value`.
    pub fn filled(width: usize, height: usize, value: [f32; 3]) -> ReportImage {
        ReportImage {
            width,
            height,
            pixels: vec![value; width * height],
        }
    }

    /// Builds an image from a function of the pixel position `(x, y)`.
    pub fn from_fn(
        width: usize,
        height: usize,
        mut f: impl FnMut(usize, usize) -> [f32; 3],
    ) -> ReportImage {
        let mut pixels = Vec::with_capacity(width * height);
        for y in 0..height {
            for x in 0..width {
                pixels.push(f(x, y));
            }
        }
        ReportImage {
            width,
            height,
            pixels,
        }
    }

    /// The pixel at `(x, y)`; panics outside the image.
    pub fn get(&self, x: usize, y: usize) -> [f32; 3] {
        assert!(
            x < self.width && y < self.height,
            "pixel ({x}, {y}) outside image"
        );
        self.pixels[y * self.width + x]
    }

    /// True when `pixels` holds exactly `width * height` values.
    pub fn is_consistent(&self) -> bool {
        self.pixels.len() == self.width * self.height
    }
}

/// How much work a method did: the unit differs between methods, so it is named.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Effort {
    /// Path tracing: samples per pixel.
    SamplesPerPixel(u64),
    /// Progressive methods (SPPM, progressive photon mapping, radiosity sweeps): passes.
    Iterations(u64),
}

impl Effort {
    /// The count, whatever its unit.
    pub fn count(self) -> u64 {
        match self {
            Effort::SamplesPerPixel(n) | Effort::Iterations(n) => n,
        }
    }

    /// Short unit label as shown in the table ("spp" or "it").
    pub fn unit(self) -> &'static str {
        match self {
            Effort::SamplesPerPixel(_) => "spp",
            Effort::Iterations(_) => "it",
        }
    }
}

/// One method's final figures against the reference (same definitions as `radiant compare`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MetricsRow {
    pub relmse: f64,
    pub rmse: f64,
    pub mae: f64,
    /// Mean ꟻLIP error, where it was computed.
    pub flip_mean: Option<f64>,
    /// Wall-clock render time in seconds.
    pub seconds: f64,
    pub effort: Effort,
}

/// The error at one progressive snapshot of a render.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Snapshot {
    /// Wall-clock seconds since the render started.
    pub seconds: f64,
    /// Samples per pixel or iterations so far, in the unit of the method's [`Effort`].
    pub samples: u64,
    pub relmse: f64,
    pub flip_mean: Option<f64>,
}

/// Everything shown for one rendering method.
#[derive(Clone, Debug, PartialEq)]
pub struct MethodResult {
    /// Display name, e.g. "path tracing" or "SPPM".
    pub name: String,
    /// The final image; error views need it to be the reference's size.
    pub image: ReportImage,
    /// Per-pixel ꟻLIP error in [0, 1] (row-major, one value per pixel), computed elsewhere.
    pub flip_map: Option<Vec<f32>>,
    pub metrics: MetricsRow,
    /// Snapshots in the order they were taken.
    pub convergence: Vec<Snapshot>,
}

/// The region, in pixels, over which the metrics were computed: `x0..x1 × y0..y1`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CropInfo {
    pub x0: usize,
    pub y0: usize,
    pub x1: usize,
    pub y1: usize,
}

/// How image data are stored in the page.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Precision {
    /// 32-bit floats: exact values, twice the size of `F16`.
    #[default]
    F32,
    /// IEEE half floats (about 3 significant digits, finite up to 65504): halves the file.
    F16,
}

/// A whole method study: the input of [`crate::write_report`].
#[derive(Clone, Debug, PartialEq)]
pub struct StudyReport {
    /// Scene name shown as the title.
    pub scene: String,
    /// Free-form lines shown under the title, e.g. how the reference was made.
    pub notes: Vec<String>,
    /// Free-form camera description, e.g. "perspective, fov 39°, 256×256".
    pub camera: Option<String>,
    /// Region the metrics were computed over, outlined in the viewer.
    pub crop: Option<CropInfo>,
    pub reference: ReportImage,
    pub methods: Vec<MethodResult>,
    pub precision: Precision,
}

impl StudyReport {
    /// Problems that make part of the report meaningless (shown as warnings in the page,
    /// which still shows everything it can). Empty for a consistent report.
    pub fn problems(&self) -> Vec<String> {
        let mut out = Vec::new();
        if !self.reference.is_consistent() {
            out.push(format!(
                "reference: {} pixel values for a {}×{} image",
                self.reference.pixels.len(),
                self.reference.width,
                self.reference.height
            ));
        }
        for m in &self.methods {
            let img = &m.image;
            if !img.is_consistent() {
                out.push(format!(
                    "{}: {} pixel values for a {}×{} image",
                    m.name,
                    img.pixels.len(),
                    img.width,
                    img.height
                ));
            }
            if (img.width, img.height) != (self.reference.width, self.reference.height) {
                out.push(format!(
                    "{}: image is {}×{}, reference is {}×{}; no error views",
                    m.name, img.width, img.height, self.reference.width, self.reference.height
                ));
            }
            if let Some(flip) = &m.flip_map
                && flip.len() != img.width * img.height
            {
                out.push(format!(
                    "{}: ꟻLIP map has {} values for {} pixels; left out",
                    m.name,
                    flip.len(),
                    img.width * img.height
                ));
            }
        }
        if let Some(c) = self.crop
            && (c.x0 >= c.x1
                || c.y0 >= c.y1
                || c.x1 > self.reference.width
                || c.y1 > self.reference.height)
        {
            out.push(format!(
                "crop [{}, {}) × [{}, {}) does not fit the {}×{} reference",
                c.x0, c.x1, c.y0, c.y1, self.reference.width, self.reference.height
            ));
        }
        out
    }
}
