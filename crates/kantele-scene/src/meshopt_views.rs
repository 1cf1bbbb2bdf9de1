//! `EXT_meshopt_compression`: buffer views stored compressed by meshoptimizer are decoded (with
//! the `meshopt` crate, the reference decoder) into plain bytes before accessors read them.
//! Sizes are charged to the budget before decoding; malformed data gives an error.

use std::collections::HashMap;

use serde_json::Value;

use crate::budget::Budget;

/// `byteStride` bytes as one element for the vertex decoder (`Default` for any size).
#[derive(Clone, Copy)]
struct Element<const N: usize>([u8; N]);

impl<const N: usize> Default for Element<N> {
    fn default() -> Self {
        Self([0; N])
    }
}

fn decode_attributes<const N: usize>(encoded: &[u8], count: usize) -> Result<Vec<u8>, String> {
    let decoded: Vec<Element<N>> = meshopt::decode_vertex_buffer(encoded, count)
        .map_err(|e| format!("cannot decode the compressed vertex data: {e:?}"))?;
    Ok(decoded.iter().flat_map(|e| e.0).collect())
}

macro_rules! by_stride {
    ($stride:expr, $encoded:expr, $count:expr, $($n:literal)*) => {
        match $stride {
            $($n => decode_attributes::<$n>($encoded, $count),)*
            other => Err(format!("byte stride {other} is not a multiple of 4 up to 256")),
        }
    };
}

/// Decodes every compressed view of the document: view index → its uncompressed bytes.
pub(crate) fn decode_views(
    document: &gltf::Document,
    buffers: &[Vec<u8>],
    budget: &mut Budget,
) -> Result<HashMap<usize, Vec<u8>>, String> {
    let mut out = HashMap::new();
    for view in document.views() {
        let Some(ext) = view.extension_value("EXT_meshopt_compression") else {
            continue;
        };
        let what = format!("buffer view {} (EXT_meshopt_compression)", view.index());
        let decoded = decode_view(ext, buffers, budget).map_err(|e| format!("{what}: {e}"))?;
        out.insert(view.index(), decoded);
    }
    Ok(out)
}

fn decode_view(ext: &Value, buffers: &[Vec<u8>], budget: &mut Budget) -> Result<Vec<u8>, String> {
    let number = |key: &str| -> Result<usize, String> {
        ext.get(key)
            .and_then(Value::as_u64)
            .and_then(|v| usize::try_from(v).ok())
            .ok_or_else(|| format!("'{key}' is missing or not a count"))
    };
    let buffer = number("buffer")?;
    let offset = ext.get("byteOffset").and_then(Value::as_u64).unwrap_or(0) as usize;
    let length = number("byteLength")?;
    let stride = number("byteStride")?;
    let count = number("count")?;
    let encoded = buffers
        .get(buffer)
        .and_then(|b| b.get(offset..offset.checked_add(length)?))
        .ok_or("the compressed bytes lie outside their buffer")?;
    let size = count
        .checked_mul(stride)
        .ok_or("the decoded size overflows")?;
    budget.charge(size as u64, 2, "decoding compressed data")?;
    let mode = ext.get("mode").and_then(Value::as_str).unwrap_or("");
    let filter = ext.get("filter").and_then(Value::as_str).unwrap_or("NONE");
    let mut bytes = match mode {
        "ATTRIBUTES" => by_stride!(stride, encoded, count,
            4 8 12 16 20 24 28 32 36 40 44 48 52 56 60 64 68 72 76 80 84 88 92 96 100 104 108
            112 116 120 124 128 132 136 140 144 148 152 156 160 164 168 172 176 180 184 188 192
            196 200 204 208 212 216 220 224 228 232 236 240 244 248 252 256)?,
        "TRIANGLES" | "INDICES" => {
            let triangles = mode == "TRIANGLES";
            let err = |e| format!("cannot decode the compressed indices: {e:?}");
            match stride {
                2 => {
                    let v: Vec<u16> = if triangles {
                        meshopt::decode_index_buffer(encoded, count).map_err(err)?
                    } else {
                        meshopt::decode_index_sequence(encoded, count).map_err(err)?
                    };
                    v.iter().flat_map(|i| i.to_le_bytes()).collect()
                }
                4 => {
                    let v: Vec<u32> = if triangles {
                        meshopt::decode_index_buffer(encoded, count).map_err(err)?
                    } else {
                        meshopt::decode_index_sequence(encoded, count).map_err(err)?
                    };
                    v.iter().flat_map(|i| i.to_le_bytes()).collect()
                }
                other => return Err(format!("index stride {other} is not 2 or 4")),
            }
        }
        other => return Err(format!("unknown mode '{other}'")),
    };
    apply_filter(filter, stride, &mut bytes)?;
    Ok(bytes)
}

/// Undoes a vertex filter in place (`NONE`, `OCTAHEDRAL`, `QUATERNION`, `EXPONENTIAL`).
fn apply_filter(filter: &str, stride: usize, bytes: &mut [u8]) -> Result<(), String> {
    match (filter, stride) {
        ("NONE", _) => Ok(()),
        ("OCTAHEDRAL", 4) => {
            let mut v: Vec<[i8; 4]> = bytes
                .chunks_exact(4)
                .map(|c| [c[0] as i8, c[1] as i8, c[2] as i8, c[3] as i8])
                .collect();
            meshopt::decode_filter_oct(&mut v);
            for (dst, src) in bytes.chunks_exact_mut(4).zip(&v) {
                dst.copy_from_slice(&src.map(|x| x as u8));
            }
            Ok(())
        }
        ("OCTAHEDRAL", 8) => {
            let mut v = shorts(bytes);
            meshopt::decode_filter_oct(&mut v);
            write_shorts(bytes, &v);
            Ok(())
        }
        ("QUATERNION", 8) => {
            let mut v = shorts(bytes);
            meshopt::decode_filter_quat(&mut v);
            write_shorts(bytes, &v);
            Ok(())
        }
        ("EXPONENTIAL", s) if s % 4 == 0 => {
            let mut v: Vec<[u32; 1]> = bytes
                .chunks_exact(4)
                .map(|c| [u32::from_le_bytes([c[0], c[1], c[2], c[3]])])
                .collect();
            // Each 32-bit component is decoded on its own, so one component at a time is the
            // same as the view's stride.
            meshopt::decode_filter_exp(&mut v);
            for (dst, src) in bytes.chunks_exact_mut(4).zip(&v) {
                dst.copy_from_slice(&src[0].to_le_bytes());
            }
            Ok(())
        }
        (other, s) => Err(format!(
            "filter {other} with byte stride {s} is not defined"
        )),
    }
}

fn shorts(bytes: &[u8]) -> Vec<[i16; 4]> {
    bytes
        .chunks_exact(8)
        .map(|c| {
            let s = |k: usize| i16::from_le_bytes([c[2 * k], c[2 * k + 1]]);
            [s(0), s(1), s(2), s(3)]
        })
        .collect()
}

fn write_shorts(bytes: &mut [u8], values: &[[i16; 4]]) {
    for (dst, src) in bytes.chunks_exact_mut(8).zip(values) {
        for k in 0..4 {
            dst[2 * k..2 * k + 2].copy_from_slice(&src[k].to_le_bytes());
        }
    }
}
