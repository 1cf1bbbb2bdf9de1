//! The loader's side of skins and animation: it reads the chosen animation and the skins,
//! records during the node walk what posing needs ([`Rig`]), gives each skinned or
//! morph-animated primitive of a node a mesh of its own, and poses the scene at the load's
//! time once the walk is done.
//!
//! Without an animation the rest pose is drawn: the file's node transforms and default morph
//! weights, with skins applied. Files without skins and without a chosen animation do not
//! build a rig at all, and load as before.

use glam::{Mat4, Quat, Vec3, Vec4};
use gltf::accessor::Dimensions;
use gltf::mesh::Semantic;
use kantele_rules::scene::Topology;

use super::clip::{self, Clip, Path};
use super::pose::{AnimationPlayer, Deform, MorphDeltas, Rig, RigDraw, RigNode, RigSkin};
use super::skin::Influences;
use super::Loader;
use crate::accessor::{read_f32, read_mat4_f32, BufferData};
use crate::mesh_util::flat_normals;
use crate::LoadError;

/// What the loader gathers for posing while it walks the nodes.
#[derive(Debug)]
pub(super) struct RigBuilder {
    rig: Rig,
    clip: Option<Clip>,
    /// Per node: the chosen animation animates its morph weights.
    weights_animated: Vec<bool>,
}

/// Whether a primitive has joint influences (any `JOINTS_n` or `WEIGHTS_n`).
fn has_influences(primitive: &gltf::Primitive) -> bool {
    primitive
        .attributes()
        .any(|(s, _)| matches!(s, Semantic::Joints(_) | Semantic::Weights(_)))
}

impl Loader<'_> {
    /// Lists the file's animations, reads the chosen one and the skins, and starts a rig when
    /// there is either.
    pub(super) fn prepare_rig(&mut self) -> Result<(), LoadError> {
        let animations = &self.patched.animations;
        for feature in clip::unplayable_paths(animations) {
            self.info.ignore(feature);
        }
        let document = self.document;
        let node_count = document.nodes().len();
        let data = BufferData {
            buffers: self.buffers,
            decoded_views: self.decoded_views,
        };
        let clip = match &self.options.animation {
            None => None,
            Some(choice) => {
                let time = self.options.time;
                if !time.is_finite() {
                    return Err(
                        self.invalid(format!("time {time} is not a finite number of seconds"))
                    );
                }
                let index = clip::choose(animations, choice).map_err(|e| self.invalid(e))?;
                let read = clip::read_clip(
                    &animations[index],
                    index,
                    node_count,
                    document,
                    &data,
                    &mut self.budget,
                );
                Some(read.map_err(|e| self.invalid(e))?)
            }
        };
        if clip.is_none() && document.skins().len() == 0 {
            return Ok(());
        }
        self.budget
            .charge(
                node_count as u64,
                160,
                "the node hierarchy of the skins and animation",
            )
            .map_err(|e| self.invalid(e))?;
        let mut parents = vec![None; node_count];
        for node in document.nodes() {
            for child in node.children() {
                parents[child.index()].get_or_insert(node.index());
            }
        }
        let nodes = document
            .nodes()
            .zip(parents)
            .map(|(node, parent)| {
                let (t, r, s) = node.transform().decomposed();
                let rotation = Vec4::from(r)
                    .try_normalize()
                    .map_or(Quat::IDENTITY, Quat::from_vec4);
                RigNode {
                    parent,
                    rest_matrix: Mat4::from_cols_array_2d(&node.transform().matrix()),
                    rest_trs: (Vec3::from(t), rotation, Vec3::from(s)),
                    rest_weights: node
                        .weights()
                        .or(node.mesh().and_then(|m| m.weights()))
                        .map(<[f32]>::to_vec)
                        .unwrap_or_default(),
                }
            })
            .collect();
        let mut skins = Vec::new();
        for skin in document.skins() {
            let joints: Vec<usize> = skin.joints().map(|j| j.index()).collect();
            let what = format!("skin {}", skin.index());
            self.budget
                .charge(joints.len() as u64, 72, &what)
                .map_err(|e| self.invalid(e))?;
            let inverse_bind = match skin.inverse_bind_matrices() {
                None => vec![Mat4::IDENTITY; joints.len()],
                Some(a) => {
                    if a.count() < joints.len() {
                        return Err(self.invalid(format!(
                            "{what} has {} inverse bind matrices for {} joints",
                            a.count(),
                            joints.len()
                        )));
                    }
                    let label = format!("{what}: inverse bind matrices (accessor {})", a.index());
                    let floats = read_mat4_f32(&data, &a, &mut self.budget, &label)
                        .map_err(|e| self.invalid(e))?;
                    floats
                        .chunks_exact(16)
                        .take(joints.len())
                        .map(Mat4::from_cols_slice)
                        .collect()
                }
            };
            skins.push(RigSkin {
                joints,
                inverse_bind,
            });
        }
        let mut weights_animated = vec![false; node_count];
        for channel in clip.iter().flat_map(|c| &c.channels) {
            if channel.path == Path::Weights {
                weights_animated[channel.node] = true;
            }
        }
        self.rig = Some(RigBuilder {
            rig: Rig {
                nodes,
                skins,
                ..Rig::default()
            },
            clip,
            weights_animated,
        });
        Ok(())
    }

    /// Records that the walk reached node `index` from `parent` (`None`: a root of the scene).
    pub(super) fn rig_visit(&mut self, index: usize, parent: Option<usize>) {
        if let Some(node) = self.rig.as_mut().and_then(|b| b.rig.nodes.get_mut(index)) {
            node.parent = parent;
        }
    }

    /// Whether `primitive` of `node` needs a mesh of its own that posing rewrites: the node is
    /// skinned and the primitive has joint influences, or the animation moves the node's morph
    /// weights and the primitive has morph targets.
    pub(super) fn deformed(&self, node: &gltf::Node, primitive: &gltf::Primitive) -> bool {
        let Some(builder) = &self.rig else {
            return false;
        };
        let skinned = node.skin().is_some() && has_influences(primitive);
        let morphed = builder.weights_animated.get(node.index()) == Some(&true)
            && primitive.morph_targets().len() > 0;
        skinned || morphed
    }

    /// Adds the mesh of one primitive of one node that posing rewrites (in its rest pose
    /// until [`Self::finish_rig`] poses it). Returns the mesh's index and whether it is skinned.
    /// Tangents are the file's, morphed and skinned with the mesh; none are generated for a
    /// deformed mesh (MikkTSpace's vertex splits would not follow the pose): without the
    /// file's, its normal texture bends in the derivative frame.
    pub(super) fn deformable_primitive(
        &mut self,
        node: &gltf::Node,
        mesh: &gltf::Mesh,
        primitive: &gltf::Primitive,
    ) -> Result<(usize, bool), LoadError> {
        let rest = self.primitive_mesh(mesh, primitive, &[])?;
        let n = rest.positions.len();
        let path = self.path;
        let what = format!(
            "node {} mesh '{}' primitive {}",
            node.index(),
            rest.name,
            primitive.index()
        );
        let data = BufferData {
            buffers: self.buffers,
            decoded_views: self.decoded_views,
        };
        let mut targets = Vec::new();
        for (t, target) in primitive.morph_targets().enumerate() {
            let mut read = |accessor: Option<gltf::Accessor>, semantic: &str| {
                let Some(a) = accessor else {
                    return Ok(None);
                };
                let label = format!("{what}: morph target {t} {semantic} accessor {}", a.index());
                if a.count() != n || a.dimensions() != Dimensions::Vec3 {
                    return Err(format!(
                        "{label} has {} {:?} elements, not {n} VEC3",
                        a.count(),
                        a.dimensions()
                    ));
                }
                read_f32(&data, &a, &mut self.budget, &label).map(Some)
            };
            let invalid = |e: String| LoadError::invalid(path, e);
            let positions = read(target.positions(), "POSITION").map_err(invalid)?;
            let normals = match rest.normals {
                Some(_) => read(target.normals(), "NORMAL").map_err(invalid)?,
                None => None,
            };
            let tangents = match rest.tangents {
                Some(_) => read(target.tangents(), "TANGENT").map_err(invalid)?,
                None => None,
            };
            targets.push(MorphDeltas {
                positions,
                normals,
                tangents,
            });
        }
        let skin = match (node.skin(), &self.rig) {
            (Some(skin), Some(builder)) if has_influences(primitive) => {
                let joint_count = builder
                    .rig
                    .skins
                    .get(skin.index())
                    .map_or(0, |s| s.joints.len());
                Influences::read(primitive, n, joint_count, &data, &mut self.budget, &what)
                    .map_err(|e| self.invalid(e))?
                    .map(|influences| (skin.index(), influences))
            }
            _ => None,
        };
        // The scene's copy, as `primitive` would make it (flat-shaded without normals).
        let flat = rest.normals.is_none() && rest.topology == Topology::Triangles;
        let (count, each) = if flat {
            (rest.indices.len() as u64, 60)
        } else {
            (n as u64, 72)
        };
        self.budget
            .charge(count, each, &what)
            .and_then(|()| self.budget.charge(rest.indices.len() as u64, 4, &what))
            .map_err(|e| self.invalid(e))?;
        let mut scene_mesh = rest.clone();
        if flat {
            flat_normals(&mut scene_mesh);
        }
        let corners = (flat && scene_mesh.normals.is_some()).then(|| rest.indices.clone());
        let skinned = skin.is_some();
        self.scene.meshes.push(scene_mesh);
        let index = self.scene.meshes.len() - 1;
        if let Some(builder) = self.rig.as_mut() {
            builder.rig.deforms.push(Deform {
                mesh: index,
                node: node.index(),
                skin,
                positions: rest.positions,
                normals: rest.normals,
                tangents: rest.tangents,
                targets,
                corners,
            });
        }
        Ok((index, skinned))
    }

    /// Records a draw of `node` (`instance`: its `EXT_mesh_gpu_instancing` transform).
    pub(super) fn rig_draw(
        &mut self,
        draw: usize,
        node: usize,
        instance: Option<Mat4>,
        skinned: bool,
    ) -> Result<(), LoadError> {
        if let Some(builder) = self.rig.as_mut() {
            self.budget
                .charge(
                    1,
                    std::mem::size_of::<RigDraw>() as u64,
                    "the draws of a node",
                )
                .map_err(|e| LoadError::invalid(self.path, e))?;
            builder.rig.draws.push(RigDraw {
                draw,
                node,
                instance,
                skinned,
            });
        }
        Ok(())
    }

    /// Records that `Scene::file_cameras[camera]` hangs on `node`.
    pub(super) fn rig_camera(&mut self, camera: usize, node: usize) {
        if let Some(builder) = self.rig.as_mut() {
            builder.rig.cameras.push((camera, node));
        }
    }

    /// Records that `Scene::lights[light]` hangs on `node`.
    pub(super) fn rig_light(&mut self, light: usize, node: usize) {
        if let Some(builder) = self.rig.as_mut() {
            builder.rig.lights.push((light, node));
        }
    }

    /// Records that the scene's directional light hangs on `node`.
    pub(super) fn rig_directional(&mut self, node: usize) {
        if let Some(builder) = self.rig.as_mut() {
            builder.rig.directional = Some(node);
        }
    }

    /// Poses the walked scene at the load's time (the rest pose without an animation) and
    /// returns the player of the chosen animation.
    pub(super) fn finish_rig(&mut self) -> Result<Option<AnimationPlayer>, LoadError> {
        let Some(RigBuilder { mut rig, clip, .. }) = self.rig.take() else {
            return Ok(None);
        };
        if clip.is_none() && !rig.deforms_anything() {
            return Ok(None);
        }
        rig.sort();
        let time = if clip.is_some() {
            self.options.time
        } else {
            0.0
        };
        rig.pose(clip.as_ref(), time, &mut self.scene)
            .map_err(|e| self.invalid(e.to_string()))?;
        Ok(clip.map(|clip| AnimationPlayer::new(rig, clip)))
    }
}
