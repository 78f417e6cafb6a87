//! Scene input: the pbrt-v4 tokenizer and parser, mesh readers (PLY, OBJ), and the
//! canonical scenes built in code. Everything ends in a [`SceneDesc`]: plain data that
//! the renderer and the radiosity solver read.

#![forbid(unsafe_code)]

pub mod budget;
pub mod builtin;
pub mod desc;
pub mod error;
pub mod gz;
pub mod mesh;
pub mod named_spectra;
pub mod obj;
pub mod params;
pub mod parser;
pub mod ply;
pub mod reflectance_spectrum;
pub mod spectrum;
pub mod subdiv;
pub mod texture;
pub mod token;

pub use desc::*;
pub use error::{FileLoc, SceneError, Warning};
pub use params::{Param, ParamSet, ParamValue};
pub use parser::{parse_file, parse_files, parse_str};
pub use texture::*;
