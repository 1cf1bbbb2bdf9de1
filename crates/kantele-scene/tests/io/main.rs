//! Integration tests of `kantele-scene`: glTF, OBJ, PLY and STL loading (valid, bad and hostile
//! files, the real-world corpus, KTX2 textures), fuzz replay, poses, the reference scenes and
//! ISA-identical pictures.
//!
//! One test binary with a module per subject: a binary per file would compile the shared
//! generic code and link every dependency into each (in a clean build, 31 test binaries took a
//! quarter of CI's compile time).

#[path = "../common/mod.rs"]
mod common;

mod animation;
mod bad_input;
mod corpus;
mod draco_files;
mod fuzz_replay;
mod gltf_files;
mod hostile_files;
mod isa_identical;
mod ktx2_files;
mod obj_files;
mod obj_materials;
mod ply_stl_files;
mod reference_scenes;
mod scene_choices;
mod spec_gloss;
mod srgb8_target;
mod texture_coordinates;
mod valid_files;
