//! Field offsets of the records shared with the kernels, in the order `kantele_layout_probe`
//! (`kernels/layout.cu`) writes them. NVRTC has no `offsetof`, so sizes are `static_assert`ed at
//! compile time and these offsets are compared on the device at start-up.

use std::mem::offset_of;

use kantele_rules::setup::TriangleSetup;

use crate::records::{DrawRecord, FrameUniforms, LevelRecord};

/// `(field, offset in Rust)` in the probe's order.
pub fn fields() -> Vec<(&'static str, u64)> {
    type T = TriangleSetup;
    type D = DrawRecord;
    type F = FrameUniforms;
    vec![
        ("TriangleSetup.area2", offset_of!(T, area2) as u64),
        ("TriangleSetup.bbox", offset_of!(T, bbox) as u64),
        (
            "TriangleSetup.pos_subpixel",
            offset_of!(T, pos_subpixel) as u64,
        ),
        ("TriangleSetup.depth", offset_of!(T, depth) as u64),
        (
            "TriangleSetup.depth_range",
            offset_of!(T, depth_range) as u64,
        ),
        ("TriangleSetup.inv_w", offset_of!(T, inv_w) as u64),
        (
            "TriangleSetup.bary_gradient",
            offset_of!(T, bary_gradient) as u64,
        ),
        ("TriangleSetup.draw", offset_of!(T, draw) as u64),
        (
            "TriangleSetup.primitive_id",
            offset_of!(T, primitive_id) as u64,
        ),
        ("TriangleSetup.flags", offset_of!(T, flags) as u64),
        ("TriangleSetup.reserved", offset_of!(T, reserved) as u64),
        (
            "DrawRecord.normal_matrix",
            offset_of!(D, normal_matrix) as u64,
        ),
        (
            "DrawRecord.base_color_factor",
            offset_of!(D, base_color_factor) as u64,
        ),
        ("DrawRecord.emissive", offset_of!(D, emissive) as u64),
        (
            "DrawRecord.alpha_cutoff",
            offset_of!(D, alpha_cutoff) as u64,
        ),
        ("DrawRecord.flags", offset_of!(D, flags) as u64),
        ("DrawRecord.texture", offset_of!(D, texture) as u64),
        ("DrawRecord.sampler", offset_of!(D, sampler) as u64),
        (
            "DrawRecord.emissive_texture",
            offset_of!(D, emissive_texture) as u64,
        ),
        (
            "DrawRecord.emissive_sampler",
            offset_of!(D, emissive_sampler) as u64,
        ),
        ("DrawRecord.node_id", offset_of!(D, node_id) as u64),
        ("DrawRecord.vertex_base", offset_of!(D, vertex_base) as u64),
        ("DrawRecord.shaded_base", offset_of!(D, shaded_base) as u64),
        ("FrameUniforms.to_light", offset_of!(F, to_light) as u64),
        ("FrameUniforms.ambient", offset_of!(F, ambient) as u64),
        ("FrameUniforms.guard_kx", offset_of!(F, guard_kx) as u64),
        (
            "FrameUniforms.clear_color",
            offset_of!(F, clear_color) as u64,
        ),
        ("FrameUniforms.width", offset_of!(F, width) as u64),
        ("FrameUniforms.pass", offset_of!(F, pass) as u64),
        (
            "FrameUniforms.chunk_count",
            offset_of!(F, chunk_count) as u64,
        ),
        ("LevelRecord.width", offset_of!(LevelRecord, width) as u64),
    ]
}

/// Compares the probe's output with [`fields`]; the error names the first field that differs.
pub fn check(device: &[u64]) -> Result<(), String> {
    let fields = fields();
    if device.len() < fields.len() {
        return Err(format!(
            "layout probe wrote {} offsets, expected {}",
            device.len(),
            fields.len()
        ));
    }
    for ((name, rust), gpu) in fields.iter().zip(device) {
        if rust != gpu {
            return Err(format!(
                "record layout differs: {name} is at byte {rust} in Rust, {gpu} in the kernels"
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn probe_order_matches_the_kernel_source() {
        // The kernel writes `OFFSET(x, field)` lines in the same order as `fields()`.
        let source = include_str!("../kernels/layout.cu");
        let written: Vec<&str> = source
            .lines()
            .filter_map(|l| l.trim().strip_prefix("out[i++] = OFFSET("))
            .map(|rest| rest.split([',', ')']).nth(1).unwrap_or("").trim())
            .collect();
        let expected: Vec<&str> = fields()
            .iter()
            .map(|(name, _)| name.split('.').nth(1).unwrap_or(""))
            .collect();
        assert_eq!(written, expected);
    }

    #[test]
    fn a_differing_offset_is_reported_by_name() {
        let mut device: Vec<u64> = fields().iter().map(|(_, o)| *o).collect();
        assert_eq!(check(&device), Ok(()));
        device[7] += 4;
        let err = check(&device).expect_err("differs");
        assert!(err.contains("TriangleSetup.draw"), "{err}");
        assert!(check(&device[..3]).is_err());
    }
}
