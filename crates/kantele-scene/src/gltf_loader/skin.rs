//! Skinning on the CPU (glTF 2.0 §3.7.3): a vertex's joint influences (every `JOINTS_n` /
//! `WEIGHTS_n` set of its primitive) and the skinned position
//! `Σ wᵢ · (jointWorldᵢ · inverseBindMatrixᵢ) · v`, its normal by the inverse transpose of the
//! same matrix and its tangent by the matrix itself, both renormalised; where the matrix mirrors
//! (negative determinant) the tangent's bitangent sign flips, so the bitangent `w (n × t)`
//! follows the matrix too.
//!
//! Weights are used as given (glTF asks exporters to normalise them; nothing is rescaled here).
//! A vertex whose weights sum to zero, or that has a non-finite weight, has no defined skinned
//! place: it is placed by the skinned node's own world matrix, as an unskinned mesh would be.

use glam::{Mat3, Mat4, Vec3, Vec4};
use gltf::accessor::{DataType, Dimensions};
use gltf::mesh::Semantic;

use crate::accessor::{read_f32, read_u32, BufferData};
use crate::budget::{vec_with_capacity, Budget};

/// The joint influences of a primitive's vertices: `4 × sets` (joint, weight) pairs each.
#[derive(Clone, Debug)]
pub(crate) struct Influences {
    /// Pairs per vertex (4 per `JOINTS_n` / `WEIGHTS_n` set).
    per_vertex: usize,
    /// Joint indices into the skin's `joints`, `per_vertex` per vertex.
    joints: Vec<u16>,
    /// Weights, `per_vertex` per vertex.
    weights: Vec<f32>,
}

impl Influences {
    /// Reads every `JOINTS_n` / `WEIGHTS_n` set of `primitive` (`vertex_count` vertices, a skin
    /// of `joint_count` joints); `None` when it has none. `what` names the primitive in errors.
    pub(crate) fn read(
        primitive: &gltf::Primitive,
        vertex_count: usize,
        joint_count: usize,
        data: &BufferData,
        budget: &mut Budget,
        what: &str,
    ) -> Result<Option<Self>, String> {
        let mut sets = 0;
        for (semantic, _) in primitive.attributes() {
            if let Semantic::Joints(k) | Semantic::Weights(k) = semantic {
                sets = sets.max(k as usize + 1);
            }
        }
        if sets == 0 {
            return Ok(None);
        }
        let per_vertex = 4 * sets;
        let total = vertex_count
            .checked_mul(per_vertex)
            .ok_or_else(|| format!("{what}: too many joint influences"))?;
        budget.charge(total as u64, 6, what)?;
        let mut joints = vec_with_capacity::<u16>(total, what)?;
        let mut weights = vec_with_capacity::<f32>(total, what)?;
        joints.resize(total, 0);
        weights.resize(total, 0.0);
        for k in 0..sets {
            let (Some(j), Some(w)) = (
                primitive.get(&Semantic::Joints(k as u32)),
                primitive.get(&Semantic::Weights(k as u32)),
            ) else {
                return Err(format!(
                    "{what}: JOINTS_{k} and WEIGHTS_{k} must come together (one is missing)"
                ));
            };
            let joint_type_ok = matches!(j.data_type(), DataType::U8 | DataType::U16)
                && !j.normalized()
                && j.dimensions() == Dimensions::Vec4;
            let weight_type_ok = (w.data_type() == DataType::F32
                || (w.normalized() && matches!(w.data_type(), DataType::U8 | DataType::U16)))
                && w.dimensions() == Dimensions::Vec4;
            if !joint_type_ok || !weight_type_ok {
                return Err(format!(
                    "{what}: JOINTS_{k} accessor {} ({:?} {:?}) or WEIGHTS_{k} accessor {} ({:?} {:?}) has a type glTF does not allow",
                    j.index(),
                    j.data_type(),
                    j.dimensions(),
                    w.index(),
                    w.data_type(),
                    w.dimensions()
                ));
            }
            for (name, count) in [("JOINTS", j.count()), ("WEIGHTS", w.count())] {
                if count != vertex_count {
                    return Err(format!(
                        "{what}: {name}_{k} has {count} elements but POSITION has {vertex_count}"
                    ));
                }
            }
            let jv = read_u32(data, &j, budget, &format!("{what}: JOINTS_{k}"))?;
            let wv = read_f32(data, &w, budget, &format!("{what}: WEIGHTS_{k}"))?;
            for v in 0..vertex_count {
                for c in 0..4 {
                    let (joint, weight) = (jv[4 * v + c], wv[4 * v + c]);
                    if weight != 0.0 && joint as usize >= joint_count {
                        return Err(format!(
                            "{what}: vertex {v} has weight {weight} on joint {joint}, but the skin has {joint_count} joints"
                        ));
                    }
                    let at = v * per_vertex + 4 * k + c;
                    // Out-of-range joints only ever come with weight 0, which is skipped.
                    joints[at] = joint.min(u16::MAX as u32) as u16;
                    weights[at] = weight;
                }
            }
        }
        Ok(Some(Self {
            per_vertex,
            joints,
            weights,
        }))
    }

    /// Number of vertices.
    pub(crate) fn vertex_count(&self) -> usize {
        self.weights.len() / self.per_vertex
    }

    /// The skinning matrix of vertex `v`, `Σ wᵢ · joint_matrices[jointᵢ]`, or `None` when its
    /// weights sum to zero or one is not finite.
    fn matrix(&self, v: usize, joint_matrices: &[Mat4]) -> Option<Mat4> {
        let range = v * self.per_vertex..(v + 1) * self.per_vertex;
        let mut cols = [Vec4::ZERO; 4];
        let mut sum = 0.0;
        for (&joint, &weight) in self.joints[range.clone()].iter().zip(&self.weights[range]) {
            if weight == 0.0 {
                continue;
            }
            if !weight.is_finite() {
                return None;
            }
            let m = joint_matrices.get(joint as usize)?;
            sum += weight;
            for (c, col) in cols.iter_mut().enumerate() {
                *col += m.col(c) * weight;
            }
        }
        (sum != 0.0).then(|| Mat4::from_cols(cols[0], cols[1], cols[2], cols[3]))
    }
}

/// The matrix that carries normals with `m`: the inverse transpose of its upper 3 × 3, up to a
/// positive factor (its cofactor matrix, sign-corrected), so it is defined for singular `m` too.
pub(crate) fn normal_matrix(m: &Mat4) -> Mat3 {
    let (c0, c1, c2) = (
        m.x_axis.truncate(),
        m.y_axis.truncate(),
        m.z_axis.truncate(),
    );
    let cofactor = Mat3::from_cols(c1.cross(c2), c2.cross(c0), c0.cross(c1));
    if c0.dot(c1.cross(c2)) < 0.0 {
        -cofactor
    } else {
        cofactor
    }
}

/// Where [`skin`] writes: positions, and normals and tangents where the mesh has them (each as
/// long as the input).
pub(crate) struct Skinned {
    pub(crate) positions: Vec<Vec3>,
    pub(crate) normals: Option<Vec<Vec3>>,
    pub(crate) tangents: Option<Vec<Vec4>>,
}

/// Skins `positions` (and `normals` and `tangents`, when given) into `out`:
/// `joint_matrices[j]` is joint `j`'s world matrix × its inverse bind matrix; vertices without a
/// defined skinning matrix are moved by `fallback` (the skinned node's world matrix). Normals
/// and tangents are renormalised (one that vanishes keeps its input value); a tangent's sign
/// flips where its matrix mirrors.
pub(crate) fn skin(
    influences: &Influences,
    joint_matrices: &[Mat4],
    fallback: &Mat4,
    positions: &[Vec3],
    normals: Option<&[Vec3]>,
    tangents: Option<&[Vec4]>,
    out: &mut Skinned,
) {
    let fallback_normals = normal_matrix(fallback);
    for (v, &p) in positions.iter().enumerate().take(influences.vertex_count()) {
        let skinned = influences.matrix(v, joint_matrices);
        let m = skinned.as_ref().unwrap_or(fallback);
        out.positions[v] = m.transform_point3(p);
        if let (Some(src), Some(dst)) = (normals, out.normals.as_mut()) {
            let nm = match skinned {
                Some(s) => normal_matrix(&s),
                None => fallback_normals,
            };
            let n = src[v];
            dst[v] = (nm * n).try_normalize().unwrap_or(n);
        }
        if let (Some(src), Some(dst)) = (tangents, out.tangents.as_mut()) {
            let t = src[v];
            let direction = m.transform_vector3(t.truncate());
            let mirrored = Mat3::from_mat4(*m).determinant() < 0.0;
            let w = if mirrored { -t.w } else { t.w };
            dst[v] = direction.try_normalize().unwrap_or(t.truncate()).extend(w);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn influences(joints: Vec<u16>, weights: Vec<f32>) -> Influences {
        Influences {
            per_vertex: 4,
            joints,
            weights,
        }
    }

    #[test]
    fn blends_joint_matrices_by_weight_and_falls_back_without_weights() {
        let joints = [
            Mat4::IDENTITY,
            Mat4::from_translation(Vec3::new(2.0, 0.0, 0.0)),
            Mat4::from_rotation_z(std::f32::consts::FRAC_PI_2),
        ];
        let inf = influences(
            vec![0, 1, 0, 0, 2, 0, 0, 0, 5, 0, 0, 0],
            vec![0.5, 0.5, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        );
        let fallback = Mat4::from_translation(Vec3::new(0.0, 0.0, 10.0));
        let positions = [Vec3::ONE; 3];
        let normals = [Vec3::X; 3];
        let tangents = [Vec4::new(0.0, 1.0, 0.0, -1.0); 3];
        let mut skinned = Skinned {
            positions: vec![Vec3::ZERO; 3],
            normals: Some(vec![Vec3::ZERO; 3]),
            tangents: Some(vec![Vec4::ZERO; 3]),
        };
        skin(
            &inf,
            &joints,
            &fallback,
            &positions,
            Some(&normals),
            Some(&tangents),
            &mut skinned,
        );
        let out = &skinned.positions;
        let out_n = skinned.normals.as_ref().expect("normals");
        let out_t = skinned.tangents.as_ref().expect("tangents");
        // The rotated vertex's tangent turns with it and keeps its sign.
        assert!(
            (out_t[1] - Vec4::new(-1.0, 0.0, 0.0, -1.0)).length() < 1e-6,
            "{}",
            out_t[1]
        );
        assert_eq!(out[0], Vec3::new(2.0, 1.0, 1.0));
        assert!(
            (out[1] - Vec3::new(-1.0, 1.0, 1.0)).length() < 1e-6,
            "{}",
            out[1]
        );
        assert!((out_n[1] - Vec3::Y).length() < 1e-6, "{}", out_n[1]);
        assert_eq!(out[2], Vec3::new(1.0, 1.0, 11.0));
        assert_eq!(out_n[2], Vec3::X);
    }

    #[test]
    fn normals_follow_the_inverse_transpose_also_when_mirrored() {
        // A non-uniform scale: a 45° normal leans towards the squashed axis.
        let m = Mat4::from_scale(Vec3::new(2.0, 1.0, 1.0));
        let n = (normal_matrix(&m) * Vec3::new(1.0, 1.0, 0.0)).normalize();
        let expected = Vec3::new(0.5, 1.0, 0.0).normalize();
        assert!((n - expected).length() < 1e-6, "{n}");
        // A mirror keeps the normal on the mirrored surface's outside.
        let mirror = Mat4::from_scale(Vec3::new(-1.0, 1.0, 1.0));
        let n = (normal_matrix(&mirror) * Vec3::X).normalize();
        assert_eq!(n, -Vec3::X);
    }

    /// A mirroring joint matrix flips the tangent's bitangent sign: `w (n × t)` of the skinned
    /// vectors is the mirrored bitangent.
    #[test]
    fn tangents_follow_the_matrix_and_flip_their_sign_when_mirrored() {
        let inf = influences(vec![0, 0, 0, 0], vec![1.0, 0.0, 0.0, 0.0]);
        let mirror = Mat4::from_scale(Vec3::new(-1.0, 1.0, 1.0));
        let (n, t) = (Vec3::Z, Vec4::new(1.0, 0.0, 0.0, 1.0));
        let mut skinned = Skinned {
            positions: vec![Vec3::ZERO],
            normals: Some(vec![Vec3::ZERO]),
            tangents: Some(vec![Vec4::ZERO]),
        };
        skin(
            &inf,
            &[mirror],
            &Mat4::IDENTITY,
            &[Vec3::ZERO],
            Some(&[n]),
            Some(&[t]),
            &mut skinned,
        );
        let n2 = skinned.normals.expect("normals")[0];
        let t2 = skinned.tangents.expect("tangents")[0];
        let bitangent = n2.cross(t2.truncate()) * t2.w;
        let mirrored_bitangent = mirror.transform_vector3(n.cross(t.truncate()) * t.w);
        assert!(
            (bitangent - mirrored_bitangent).length() < 1e-6,
            "{bitangent}"
        );
        assert_eq!(t2.truncate(), -Vec3::X);
    }
}
