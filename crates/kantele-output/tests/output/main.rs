//! Tests of the output crate: camera poses, their conventions and the sidecar reader.

mod pose;
