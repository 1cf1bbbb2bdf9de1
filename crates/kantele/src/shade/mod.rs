//! Shading resources.
pub mod texture;
