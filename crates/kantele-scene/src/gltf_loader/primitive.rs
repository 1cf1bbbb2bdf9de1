//! Mesh primitives: attribute types and counts, morph targets, indices and topologies.

use glam::{Vec2, Vec3, Vec4};
use gltf::accessor::{DataType, Dimensions};
use gltf::mesh::{Mode, Semantic};
use kantele_rules::scene::{Mesh, Shading, Topology};

use super::material::UvMap;
use super::{morph, named, Loader};
use crate::accessor::{read_f32, read_u32, BufferData};
use crate::mesh_util::{
    fan_to_list, first_index_out_of_range, flat_normals, line_strip_to_list, strip_to_list,
};
use crate::{tangents, LoadError};

impl Loader<'_> {
    /// Converts one primitive (triangles, lines or points) to a scene mesh.
    pub(super) fn primitive(
        &mut self,
        mesh: &gltf::Mesh,
        primitive: &gltf::Primitive,
        weights: &[f32],
    ) -> Result<Option<usize>, LoadError> {
        let mut converted = self.primitive_mesh(mesh, primitive, weights)?;
        let what = format!("mesh '{}' primitive {}", converted.name, primitive.index());
        if converted.normals.is_none() && converted.topology == Topology::Triangles {
            // De-indexed: one vertex (position, normal, texcoords, colour) per corner.
            self.budget
                .charge(converted.indices.len() as u64, 56, &what)
                .map_err(|e| self.invalid(e))?;
            flat_normals(&mut converted);
        }
        // Tangents only serve PBR shading (MikkTSpace takes about 1.5 s per million
        // triangles).
        if converted.tangents.is_none() && self.shading() == Shading::Pbr {
            if let Some(set) = self.normal_map_of(converted.material) {
                tangents::generate(&mut converted, set, &mut self.budget, &what)
                    .map_err(|e| self.invalid(e))?;
            }
        }
        self.scene.meshes.push(converted);
        Ok(Some(self.scene.meshes.len() - 1))
    }

    /// Which texture coordinate set of its meshes material `material` bends normals with
    /// (its normal texture's), if it has a normal texture.
    pub(super) fn normal_map_of(&self, material: usize) -> Option<usize> {
        self.material_normal_map.get(material).copied().flatten()
    }

    /// One primitive as a mesh with the given morph weights, indexed as in the file (lists),
    /// without made-up normals or tangents: what [`Self::primitive`] adds to the scene, before
    /// flat shading and tangent generation. The file's tangents are read where the material
    /// bends normals and the primitive has normals (glTF ignores tangents without them).
    pub(super) fn primitive_mesh(
        &mut self,
        mesh: &gltf::Mesh,
        primitive: &gltf::Primitive,
        weights: &[f32],
    ) -> Result<Mesh, LoadError> {
        let mesh_name = named(mesh.name(), "mesh", mesh.index());
        let what = format!("mesh '{mesh_name}' primitive {}", primitive.index());
        let mode = primitive.mode();
        let own = primitive.material().index();
        let material = match self.variant_material(primitive, &what)?.or(own) {
            Some(m) => m,
            None => self.default_material(),
        };
        let maps = self.material_uv.get(material).copied().unwrap_or_default();
        // Without textures, TEXCOORD_0 as it is.
        let maps = [Some(maps[0].unwrap_or(UvMap::PLAIN)), maps[1]];
        let bends_normals = self.normal_map_of(material).is_some();

        let check = |semantic: &str,
                     accessor: &gltf::Accessor,
                     allowed: &[(DataType, bool)],
                     dims: &[Dimensions]|
         -> Result<(), LoadError> {
            let ty = accessor.data_type();
            let normalized = accessor.normalized() && ty != DataType::F32;
            let ok_type =
                allowed.contains(&(ty, normalized)) && dims.contains(&accessor.dimensions());
            if !ok_type {
                return Err(self.invalid(format!(
                    "{what}: {semantic} accessor {} has type {:?} {:?}{}, which glTF (with KHR_mesh_quantization) does not allow",
                    accessor.index(),
                    ty,
                    accessor.dimensions(),
                    if accessor.normalized() { " (normalized)" } else { "" }
                )));
            }
            if accessor.count() == 0 {
                return Err(self.invalid(format!(
                    "{what}: {semantic} accessor {} is empty",
                    accessor.index()
                )));
            }
            Ok(())
        };
        use DataType::{F32, I16, I8, U16, U32, U8};
        // Types of glTF 2.0 plus KHR_mesh_quantization, as (component type, normalized).
        let any_int = [
            (F32, false),
            (I8, false),
            (I8, true),
            (U8, false),
            (U8, true),
            (I16, false),
            (I16, true),
            (U16, false),
            (U16, true),
        ];
        let normal_types = [(F32, false), (I8, true), (I16, true)];
        let color_types = [(F32, false), (U8, true), (U16, true)];
        let index_types = [(U8, false), (U16, false), (U32, false)];

        let Some(position_accessor) = primitive.get(&Semantic::Positions) else {
            return Err(self.invalid(format!("{what} has no POSITION attribute")));
        };
        check(
            "POSITION",
            &position_accessor,
            &any_int,
            &[Dimensions::Vec3],
        )?;
        let normal_accessor = primitive.get(&Semantic::Normals);
        if let Some(a) = &normal_accessor {
            check("NORMAL", a, &normal_types, &[Dimensions::Vec3])?;
        }
        // Per map of the material: the accessor of its TEXCOORD_n set, with that name.
        let mut texcoord_accessors = Vec::with_capacity(maps.len());
        for map in maps.iter().flatten() {
            let name = format!("TEXCOORD_{}", map.set);
            let accessor = primitive.get(&Semantic::TexCoords(map.set));
            if let Some(a) = &accessor {
                check(&name, a, &any_int, &[Dimensions::Vec2])?;
            }
            texcoord_accessors.push((name, accessor, map.transform));
        }
        let tangent_accessor = match (&normal_accessor, bends_normals) {
            (Some(_), true) => primitive.get(&Semantic::Tangents),
            _ => None,
        };
        if let Some(a) = &tangent_accessor {
            check("TANGENT", a, &normal_types, &[Dimensions::Vec4])?;
        }
        let color_accessor = primitive.get(&Semantic::Colors(0));
        if let Some(a) = &color_accessor {
            check(
                "COLOR_0",
                a,
                &color_types,
                &[Dimensions::Vec3, Dimensions::Vec4],
            )?;
        }
        let index_accessor = primitive.indices();
        if let Some(a) = &index_accessor {
            check("index", a, &index_types, &[Dimensions::Scalar])?;
        }

        let data = BufferData {
            buffers: self.buffers,
            decoded_views: self.decoded_views,
        };
        let n = position_accessor.count();
        let mut read = |semantic: &str, accessor: &gltf::Accessor| {
            let label = format!("{what}: {semantic} accessor {}", accessor.index());
            read_f32(&data, accessor, &mut self.budget, &label)
        };
        let positions: Vec<Vec3> = read("POSITION", &position_accessor)
            .map_err(|e| LoadError::invalid(self.path, e))?
            .chunks_exact(3)
            .map(Vec3::from_slice)
            .collect();
        let count_error = |semantic: &str, len: usize| {
            LoadError::invalid(
                self.path,
                format!("{what}: {semantic} has {len} elements but POSITION has {n}"),
            )
        };
        let normals = match &normal_accessor {
            Some(a) if a.count() != n => return Err(count_error("NORMAL", a.count())),
            Some(a) => Some(
                read("NORMAL", a)
                    .map_err(|e| LoadError::invalid(self.path, e))?
                    .chunks_exact(3)
                    .map(Vec3::from_slice)
                    .collect::<Vec<_>>(),
            ),
            None => None,
        };
        let mut texcoord_sets: Vec<Option<Vec<Vec2>>> = Vec::with_capacity(2);
        for (name, accessor, transform) in &texcoord_accessors {
            texcoord_sets.push(match accessor {
                Some(a) if a.count() != n => return Err(count_error(name, a.count())),
                Some(a) => Some(
                    read(name, a)
                        .map_err(|e| LoadError::invalid(self.path, e))?
                        .chunks_exact(2)
                        .map(|t| transform.transform_point2(Vec2::from_slice(t)))
                        .collect::<Vec<_>>(),
                ),
                None => None,
            });
        }
        let mut texcoord_sets = texcoord_sets.into_iter();
        let texcoords = texcoord_sets.next().flatten();
        let texcoords1 = texcoord_sets.next().flatten();
        let mut tangents = match &tangent_accessor {
            Some(a) if a.count() != n => return Err(count_error("TANGENT", a.count())),
            Some(a) => Some(
                read("TANGENT", a)
                    .map_err(|e| LoadError::invalid(self.path, e))?
                    .chunks_exact(4)
                    .map(Vec4::from_slice)
                    .collect::<Vec<_>>(),
            ),
            None => None,
        };
        let (mut positions, mut normals) = (positions, normals);
        for (target, &weight) in primitive.morph_targets().zip(weights) {
            if !morph::applies(weight) {
                continue;
            }
            let mut apply = |accessor: Option<gltf::Accessor>,
                             values: &mut [Vec3],
                             semantic: &str|
             -> Result<(), LoadError> {
                let Some(a) = accessor else { return Ok(()) };
                if a.count() != n || a.dimensions() != Dimensions::Vec3 {
                    return Err(count_error(semantic, a.count()));
                }
                let deltas = read(semantic, &a).map_err(|e| LoadError::invalid(self.path, e))?;
                morph::add_target(values, &deltas, weight);
                Ok(())
            };
            apply(target.positions(), &mut positions, "morph target POSITION")?;
            if let Some(normals) = normals.as_mut() {
                apply(target.normals(), normals, "morph target NORMAL")?;
            }
            if let Some(tangents) = tangents.as_mut() {
                let mut directions: Vec<Vec3> = tangents.iter().map(|t| t.truncate()).collect();
                apply(target.tangents(), &mut directions, "morph target TANGENT")?;
                for (t, d) in tangents.iter_mut().zip(directions) {
                    *t = d.extend(t.w);
                }
            }
        }
        let colors = match &color_accessor {
            Some(a) if a.count() != n => return Err(count_error("COLOR_0", a.count())),
            Some(a) => {
                let flat = read("COLOR_0", a).map_err(|e| LoadError::invalid(self.path, e))?;
                Some(if a.dimensions() == Dimensions::Vec3 {
                    flat.chunks_exact(3)
                        .map(|c| Vec4::new(c[0], c[1], c[2], 1.0))
                        .collect::<Vec<_>>()
                } else {
                    flat.chunks_exact(4).map(Vec4::from_slice).collect()
                })
            }
            None => None,
        };
        let vertex_indices: Vec<u32> = match &index_accessor {
            Some(a) => {
                let label = format!("{what}: index accessor {}", a.index());
                read_u32(&data, a, &mut self.budget, &label)
                    .map_err(|e| LoadError::invalid(self.path, e))?
            }
            None => {
                let n = u32::try_from(n).map_err(|_| {
                    self.invalid(format!("{what}: too many vertices for 32-bit indices"))
                })?;
                self.budget
                    .charge(n as u64, 4, &what)
                    .map_err(|e| LoadError::invalid(self.path, e))?;
                (0..n).collect()
            }
        };
        if positions.iter().any(|p| !p.is_finite()) {
            self.info.warn(format!(
                "{what}: some positions are infinite or NaN; triangles using them are not drawn"
            ));
        }
        // Strips, fans and loops are unrolled into lists: charge the list first (three
        // indices per triangle, two per line).
        let unrolled = match mode {
            Mode::TriangleStrip | Mode::TriangleFan => vertex_indices.len().saturating_sub(2) * 3,
            Mode::LineStrip | Mode::LineLoop => vertex_indices.len() * 2,
            _ => 0,
        };
        self.budget
            .charge(unrolled as u64, 4, &what)
            .map_err(|e| LoadError::invalid(self.path, e))?;
        let (indices, topology) = match mode {
            Mode::TriangleStrip => (strip_to_list(&vertex_indices), Topology::Triangles),
            Mode::TriangleFan => (fan_to_list(&vertex_indices), Topology::Triangles),
            Mode::LineStrip => (line_strip_to_list(&vertex_indices, false), Topology::Lines),
            Mode::LineLoop => (line_strip_to_list(&vertex_indices, true), Topology::Lines),
            Mode::Points => (vertex_indices, Topology::Points),
            Mode::Lines | Mode::Triangles => {
                let topology = if mode == Mode::Lines {
                    Topology::Lines
                } else {
                    Topology::Triangles
                };
                let per = topology.vertices_per_primitive();
                if !vertex_indices.len().is_multiple_of(per) {
                    return Err(self.invalid(format!(
                        "{what}: {} indices do not make whole {}",
                        vertex_indices.len(),
                        topology.name()
                    )));
                }
                (vertex_indices, topology)
            }
        };
        if let Some((position, index)) = first_index_out_of_range(&indices, n) {
            return Err(self.invalid(format!(
                "{what}: index {index} at position {position} is out of range for {n} vertices"
            )));
        }
        Ok(Mesh {
            name: mesh_name,
            positions,
            normals,
            texcoords,
            texcoords1,
            tangents,
            colors,
            indices,
            topology,
            material,
        })
    }
}
