//! Kantele's outputs: what a rendered frame becomes on disk.
//!
//! - [`output`] — image and array files (PNG, OpenEXR, PFM, NumPy `.npy`), written atomically,
//!   one file or a frame's files together ([`output::OutputSet`]).
//! - [`row_writer`] — the same formats written a band of rows at a time, for pictures too big
//!   to hold whole.
//! - [`pose`] — [`CameraPose`](pose::CameraPose), the one camera of the command, its JSON
//!   sidecar and the Python package, with every convention (OpenGL and OpenCV matrices,
//!   intrinsics, depth kinds), framing of a model, and the sidecar and pose-list reader.
//!
//! Nothing here knows the command line: the CLI and the Python package call the same functions.
#![warn(missing_docs)]
#![forbid(unsafe_code)]

pub mod output;
pub mod pose;
pub mod row_writer;
