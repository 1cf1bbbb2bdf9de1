//! Shading resources: textures, their 8-bit texel format and the samplers that read them.
mod sample_lanes;
pub mod texel;
pub mod texture;
