//! Reading glTF accessors into plain vectors, without the `gltf` crate's reader: every component
//! type and normalization that glTF and `KHR_mesh_quantization` allow, byte strides, accessors
//! without a buffer view (zero-filled, as the spec says), sparse accessors on top, and views
//! decoded from `EXT_meshopt_compression`. Every size is checked against the buffers and charged
//! to the load's [`Budget`] before anything is allocated.

use std::collections::HashMap;

use gltf::accessor::{DataType, Dimensions};

use crate::budget::{vec_with_capacity, Budget};

/// The bytes accessors read from: the file's buffers and the views decoded from compressed
/// ones.
pub(crate) struct BufferData<'a> {
    /// The file's buffers, by index.
    pub buffers: &'a [Vec<u8>],
    /// `EXT_meshopt_compression` views, decoded (view index → bytes).
    pub decoded_views: &'a HashMap<usize, Vec<u8>>,
}

impl BufferData<'_> {
    /// The bytes of a buffer view and its stride (`None` when tightly packed).
    pub(crate) fn view(&self, view: &gltf::buffer::View) -> Result<&[u8], String> {
        if let Some(decoded) = self.decoded_views.get(&view.index()) {
            return Ok(decoded);
        }
        self.buffers
            .get(view.buffer().index())
            .and_then(|b| b.get(view.offset()..view.offset().checked_add(view.length())?))
            .ok_or_else(|| {
                format!(
                    "buffer view {} lies outside its buffer (or the buffer has no data)",
                    view.index()
                )
            })
    }
}

/// Bytes of one component.
fn component_size(ty: DataType) -> usize {
    match ty {
        DataType::I8 | DataType::U8 => 1,
        DataType::I16 | DataType::U16 => 2,
        DataType::U32 | DataType::F32 => 4,
    }
}

/// One component as `f32`, normalized as glTF defines it when `normalized`.
fn component_f32(bytes: &[u8], ty: DataType, normalized: bool) -> f32 {
    match ty {
        DataType::I8 => {
            let v = bytes[0] as i8 as f32;
            if normalized {
                (v / 127.0).max(-1.0)
            } else {
                v
            }
        }
        DataType::U8 => {
            let v = bytes[0] as f32;
            if normalized {
                v / 255.0
            } else {
                v
            }
        }
        DataType::I16 => {
            let v = i16::from_le_bytes([bytes[0], bytes[1]]) as f32;
            if normalized {
                (v / 32767.0).max(-1.0)
            } else {
                v
            }
        }
        DataType::U16 => {
            let v = u16::from_le_bytes([bytes[0], bytes[1]]) as f32;
            if normalized {
                v / 65535.0
            } else {
                v
            }
        }
        DataType::U32 => u32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]) as f32,
        DataType::F32 => f32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]),
    }
}

/// One unsigned integer component (index types).
fn component_u32(bytes: &[u8], ty: DataType) -> u32 {
    match ty {
        DataType::U8 => bytes[0] as u32,
        DataType::U16 => u16::from_le_bytes([bytes[0], bytes[1]]) as u32,
        _ => u32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]),
    }
}

/// Where `count` elements of `element` bytes lie in `bytes`, from `offset` with `stride`
/// (`None` or 0: tightly packed); an error when they do not fit.
fn checked_layout(
    bytes: &[u8],
    offset: usize,
    stride: Option<usize>,
    element: usize,
    count: usize,
) -> Result<usize, String> {
    let stride = stride.filter(|&s| s > 0).unwrap_or(element);
    if stride < element {
        return Err(format!(
            "byte stride {stride} is smaller than its {element}-byte elements"
        ));
    }
    if count == 0 {
        return Ok(stride);
    }
    let end = (count - 1)
        .checked_mul(stride)
        .and_then(|v| v.checked_add(offset))
        .and_then(|v| v.checked_add(element));
    match end {
        Some(end) if end <= bytes.len() => Ok(stride),
        _ => Err(format!(
            "{count} elements of {element} bytes (stride {stride}) from byte {offset} do not fit in {} bytes",
            bytes.len()
        )),
    }
}

/// Reads an accessor's components as `f32` (normalized integers mapped as glTF says), flat:
/// `count × components` values. `what` names it in errors.
pub(crate) fn read_f32(
    data: &BufferData,
    accessor: &gltf::Accessor,
    budget: &mut Budget,
    what: &str,
) -> Result<Vec<f32>, String> {
    let ty = accessor.data_type();
    let normalized = accessor.normalized();
    read_generic(data, accessor, budget, what, 0.0, |b| {
        component_f32(b, ty, normalized)
    })
}

/// Reads an index accessor (unsigned byte, short or int scalars).
pub(crate) fn read_u32(
    data: &BufferData,
    accessor: &gltf::Accessor,
    budget: &mut Budget,
    what: &str,
) -> Result<Vec<u32>, String> {
    let ty = accessor.data_type();
    read_generic(data, accessor, budget, what, 0, |b| component_u32(b, ty))
}

/// Reads a float `MAT4` accessor (inverse bind matrices): 16 column-major floats per element.
pub(crate) fn read_mat4_f32(
    data: &BufferData,
    accessor: &gltf::Accessor,
    budget: &mut Budget,
    what: &str,
) -> Result<Vec<f32>, String> {
    if accessor.dimensions() != Dimensions::Mat4 || accessor.data_type() != DataType::F32 {
        return Err(format!(
            "{what}: {:?} {:?} accessor, not float MAT4",
            accessor.data_type(),
            accessor.dimensions()
        ));
    }
    // Four-byte components: columns lie back to back, with no padding to skip.
    read_elements(data, accessor, budget, what, 0.0, |b| {
        component_f32(b, DataType::F32, false)
    })
}

fn read_generic<T: Copy>(
    data: &BufferData,
    accessor: &gltf::Accessor,
    budget: &mut Budget,
    what: &str,
    zero: T,
    convert: impl Fn(&[u8]) -> T,
) -> Result<Vec<T>, String> {
    if matches!(
        accessor.dimensions(),
        Dimensions::Mat2 | Dimensions::Mat3 | Dimensions::Mat4
    ) {
        return Err(format!("{what}: matrix accessors are not vertex data"));
    }
    read_elements(data, accessor, budget, what, zero, convert)
}

/// Reads every element (components back to back) and applies the sparse part.
fn read_elements<T: Copy>(
    data: &BufferData,
    accessor: &gltf::Accessor,
    budget: &mut Budget,
    what: &str,
    zero: T,
    convert: impl Fn(&[u8]) -> T,
) -> Result<Vec<T>, String> {
    let components = accessor.dimensions().multiplicity();
    let size = component_size(accessor.data_type());
    let element = components * size;
    let count = accessor.count();
    let total = count
        .checked_mul(components)
        .ok_or_else(|| format!("{what}: {count} elements is too many"))?;
    budget.charge(total as u64, std::mem::size_of::<T>() as u64, what)?;
    let mut out = vec_with_capacity::<T>(total, what)?;
    match accessor.view() {
        Some(view) => {
            let bytes = data.view(&view).map_err(|e| format!("{what}: {e}"))?;
            let stride = checked_layout(bytes, accessor.offset(), view.stride(), element, count)
                .map_err(|e| format!("{what}: {e}"))?;
            for i in 0..count {
                let start = accessor.offset() + i * stride;
                for c in 0..components {
                    out.push(convert(&bytes[start + c * size..]));
                }
            }
        }
        None => out.resize(total, zero),
    }
    if let Some(sparse) = accessor.sparse() {
        let n = sparse.count();
        if n > count {
            return Err(format!(
                "{what}: the sparse part replaces {n} elements of {count}"
            ));
        }
        budget.charge(n as u64, 4, what)?;
        let index_type = sparse.indices().index_type();
        let index_size = match index_type {
            gltf::accessor::sparse::IndexType::U8 => 1,
            gltf::accessor::sparse::IndexType::U16 => 2,
            gltf::accessor::sparse::IndexType::U32 => 4,
        };
        let index_view = sparse.indices().view();
        let index_bytes = data.view(&index_view).map_err(|e| format!("{what}: {e}"))?;
        let index_offset = sparse.indices().offset();
        checked_layout(index_bytes, index_offset, None, index_size, n)
            .map_err(|e| format!("{what}: sparse indices: {e}"))?;
        let value_view = sparse.values().view();
        let value_bytes = data.view(&value_view).map_err(|e| format!("{what}: {e}"))?;
        let value_offset = sparse.values().offset();
        checked_layout(value_bytes, value_offset, None, element, n)
            .map_err(|e| format!("{what}: sparse values: {e}"))?;
        for k in 0..n {
            let at = &index_bytes[index_offset + k * index_size..];
            let target = match index_type {
                gltf::accessor::sparse::IndexType::U8 => at[0] as usize,
                gltf::accessor::sparse::IndexType::U16 => {
                    u16::from_le_bytes([at[0], at[1]]) as usize
                }
                gltf::accessor::sparse::IndexType::U32 => {
                    u32::from_le_bytes([at[0], at[1], at[2], at[3]]) as usize
                }
            };
            if target >= count {
                return Err(format!(
                    "{what}: sparse index {target} is out of range for {count} elements"
                ));
            }
            let start = value_offset + k * element;
            for c in 0..components {
                out[target * components + c] = convert(&value_bytes[start + c * size..]);
            }
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normalized_components_follow_the_gltf_rules() {
        assert_eq!(component_f32(&[127], DataType::I8, true), 1.0);
        assert_eq!(component_f32(&[0x80], DataType::I8, true), -1.0);
        assert_eq!(component_f32(&[0x81], DataType::I8, true), -1.0);
        assert_eq!(component_f32(&[255], DataType::U8, true), 1.0);
        assert_eq!(component_f32(&[0xff, 0x7f], DataType::I16, true), 1.0);
        assert_eq!(component_f32(&[0x00, 0x80], DataType::I16, true), -1.0);
        assert_eq!(component_f32(&[0xff, 0xff], DataType::U16, true), 1.0);
        assert_eq!(component_f32(&[0x00, 0x80], DataType::I16, false), -32768.0);
        assert_eq!(component_f32(&[200], DataType::U8, false), 200.0);
        assert_eq!(component_u32(&[1, 1], DataType::U16), 257);
    }

    #[test]
    fn layouts_that_do_not_fit_are_refused() {
        let bytes = [0u8; 16];
        assert_eq!(checked_layout(&bytes, 0, None, 4, 4), Ok(4));
        assert_eq!(checked_layout(&bytes, 0, Some(8), 4, 2), Ok(8));
        assert!(checked_layout(&bytes, 1, None, 4, 4).is_err());
        assert!(checked_layout(&bytes, 0, Some(2), 4, 2).is_err());
        assert!(checked_layout(&bytes, 0, None, 4, usize::MAX).is_err());
    }
}
