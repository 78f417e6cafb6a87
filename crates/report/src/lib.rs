//! The viewing side of radiant's method study.
//!
//! - [`write_report`] turns a [`StudyReport`] — what `radiant study` measured for path
//!   tracing, photon mapping, SPPM, radiosity … against one reference — into a single
//!   self-contained HTML file: a synchronized zoom/pan viewer with exposure and pixel
//!   readout, an A/B swipe, false-colour error views (relative squared error, ꟻLIP), the
//!   metrics table and log–log convergence plots. Open it with `#selftest` appended to
//!   the URL and the page checks itself and writes a JSON result into
//!   `<pre id="selftest-result">`.
//! - [`tev`] sends images to a running tev viewer while a render progresses, and gives
//!   up quietly if the viewer goes away.
//!
//! The page's script and style live in `src/assets/` and are inlined verbatim.

mod encode;
mod html;
mod plot;
mod study;
mod table;
pub mod tev;
mod text;

pub use encode::{f16_bits_to_f32, f32_to_f16_bits, stored_value};
pub use html::{METHOD_COLORS, method_color, write_report};
pub use plot::fitted_slope;
pub use study::{
    CropInfo, Effort, MethodResult, MetricsRow, Precision, ReportImage, Snapshot, StudyReport,
};
pub use table::efficiency;
