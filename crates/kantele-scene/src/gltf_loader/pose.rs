//! Posing a loaded scene: the nodes' transforms and morph weights at a time of an animation
//! (their rest values where no channel animates them), the world matrices that follow, and
//! what depends on them: draws' model matrices, skinned and morphed meshes, file cameras and
//! lights.
//!
//! [`Rig`] holds what the loader recorded about the file (no reference to the document), so a
//! scene can be posed again and again after loading ([`AnimationPlayer::pose`]). Posing is plain
//! sequential `f32` arithmetic: the same time gives the same bits, and loading at a time gives
//! the same scene as loading and then posing at that time.

use glam::{Mat4, Quat, Vec3, Vec4};
use kantele_rules::scene::{Light, Scene};
use thiserror::Error;

use super::clip::{Clip, Path};
use super::morph;
use super::skin::{self, Influences};

/// A node's rest transform and place in the hierarchy.
#[derive(Clone, Debug)]
pub(crate) struct RigNode {
    /// Its parent: the node the loader's walk reached it from, else the file's parent.
    pub parent: Option<usize>,
    /// The file's local matrix (as the loader's walk uses it).
    pub rest_matrix: Mat4,
    /// The same as translation, rotation and scale (what animation channels replace).
    pub rest_trs: (Vec3, Quat, Vec3),
    /// Default morph weights: the node's, else its mesh's.
    pub rest_weights: Vec<f32>,
}

/// A skin: its joints (node indices) and inverse bind matrices, one each.
#[derive(Clone, Debug)]
pub(crate) struct RigSkin {
    /// Joint nodes.
    pub joints: Vec<usize>,
    /// Inverse bind matrices (the identity where the file gives none).
    pub inverse_bind: Vec<Mat4>,
}

/// Morph target displacements of one primitive (three floats per vertex).
#[derive(Clone, Debug)]
pub(crate) struct MorphDeltas {
    /// POSITION displacements, if the target has them.
    pub positions: Option<Vec<f32>>,
    /// NORMAL displacements, if the target has them and the mesh has normals.
    pub normals: Option<Vec<f32>>,
    /// TANGENT displacements (of `xyz`), if the target has them and the mesh has tangents.
    pub tangents: Option<Vec<f32>>,
}

/// A scene mesh that posing rewrites: one primitive of one node, morphed and perhaps skinned.
#[derive(Clone, Debug)]
pub(crate) struct Deform {
    /// Index into `Scene::meshes`.
    pub mesh: usize,
    /// The node drawing it (its morph weights; its world matrix places unskinned vertices).
    pub node: usize,
    /// The skin (index into [`Rig::skins`]) and the vertices' joint influences.
    pub skin: Option<(usize, Influences)>,
    /// The primitive's positions, before morphing and skinning.
    pub positions: Vec<Vec3>,
    /// Its normals, if it has them.
    pub normals: Option<Vec<Vec3>>,
    /// Its tangents, if the file gives them and the material bends normals.
    pub tangents: Option<Vec<Vec4>>,
    /// Its morph targets.
    pub targets: Vec<MorphDeltas>,
    /// For a mesh drawn flat-shaded (no normals in the file): the primitive's triangle list;
    /// scene vertex `i` is primitive vertex `corners[i]` and takes its triangle's normal.
    pub corners: Option<Vec<u32>>,
}

/// One draw and where its model matrix comes from.
#[derive(Clone, Debug)]
pub(crate) struct RigDraw {
    /// Index into `Scene::draws`.
    pub draw: usize,
    /// The node that draws it.
    pub node: usize,
    /// Its `EXT_mesh_gpu_instancing` transform, if any.
    pub instance: Option<Mat4>,
    /// Its mesh is skinned: the vertices are in world space and the node's matrix is not
    /// applied.
    pub skinned: bool,
}

/// What posing needs to know about the file and the loaded scene.
#[derive(Clone, Debug, Default)]
pub(crate) struct Rig {
    /// Every node of the file.
    pub nodes: Vec<RigNode>,
    /// Node indices, each after its parent (filled by [`Rig::sort`]).
    pub order: Vec<usize>,
    /// The file's skins.
    pub skins: Vec<RigSkin>,
    /// Meshes that posing rewrites.
    pub deforms: Vec<Deform>,
    /// Every draw of the scene.
    pub draws: Vec<RigDraw>,
    /// `(index into Scene::file_cameras, node)`.
    pub cameras: Vec<(usize, usize)>,
    /// `(index into Scene::lights, node)`.
    pub lights: Vec<(usize, usize)>,
    /// The node of the directional light that `Scene::light` is, if any.
    pub directional: Option<usize>,
}

/// Why a scene could not be posed.
#[derive(Debug, Error)]
pub enum PoseError {
    /// The time is NaN or infinite.
    #[error("time {0} is not a finite number of seconds")]
    Time(f32),
    /// The scene is not the one this player was loaded with (or was changed since).
    #[error("the scene does not match the animation: {0}")]
    Mismatch(String),
}

impl Rig {
    /// Orders the nodes so that each comes after its parent; a parent link that would close a
    /// loop is dropped (that node is taken as a root).
    pub(crate) fn sort(&mut self) {
        let n = self.nodes.len();
        // 0: not placed, 1: on the current path, 2: placed.
        let mut state = vec![0u8; n];
        let mut path = Vec::new();
        self.order.clear();
        for start in 0..n {
            let mut at = start;
            while state[at] == 0 {
                state[at] = 1;
                path.push(at);
                match self.nodes[at].parent {
                    Some(p) if p < n && state[p] == 1 => {
                        self.nodes[at].parent = None;
                        break;
                    }
                    Some(p) if p < n => at = p,
                    _ => {
                        self.nodes[at].parent = None;
                        break;
                    }
                }
            }
            while let Some(node) = path.pop() {
                state[node] = 2;
                self.order.push(node);
            }
        }
    }

    /// Whether anything depends on the pose (a skinned or morphed mesh); without an animation
    /// a rig with nothing to deform leaves the scene as loaded.
    pub(crate) fn deforms_anything(&self) -> bool {
        !self.deforms.is_empty()
    }

    /// Poses `scene` at `time` of `clip` (the rest pose without one).
    pub(crate) fn pose(
        &self,
        clip: Option<&Clip>,
        time: f32,
        scene: &mut Scene,
    ) -> Result<(), PoseError> {
        if !time.is_finite() {
            return Err(PoseError::Time(time));
        }
        self.check(scene)?;
        let n = self.nodes.len();
        let mut trs: Vec<Option<(Vec3, Quat, Vec3)>> = vec![None; n];
        let mut weights: Vec<Option<Vec<f32>>> = vec![None; n];
        for channel in clip.iter().flat_map(|c| &c.channels) {
            let Some(node) = self.nodes.get(channel.node) else {
                continue;
            };
            if channel.path == Path::Weights {
                let mut w = vec![0.0; channel.keys.width()];
                channel.keys.sample(time, &mut w);
                weights[channel.node] = Some(w);
                continue;
            }
            let (t, r, s) = trs[channel.node].get_or_insert(node.rest_trs);
            let mut v = [0.0; 3];
            match channel.path {
                Path::Translation => {
                    channel.keys.sample(time, &mut v);
                    *t = Vec3::from_array(v);
                }
                Path::Scale => {
                    channel.keys.sample(time, &mut v);
                    *s = Vec3::from_array(v);
                }
                Path::Rotation => *r = channel.keys.sample_rotation(time),
                Path::Weights => {}
            }
        }
        let mut world = vec![Mat4::IDENTITY; n];
        for &i in &self.order {
            let node = &self.nodes[i];
            let local = trs[i].map_or(node.rest_matrix, |(t, r, s)| {
                Mat4::from_scale_rotation_translation(s, r, t)
            });
            let parent = node.parent.map_or(Mat4::IDENTITY, |p| world[p]);
            world[i] = parent * local;
        }
        for d in &self.draws {
            scene.draws[d.draw].model = match (d.skinned, d.instance) {
                (true, instance) => instance.unwrap_or(Mat4::IDENTITY),
                (false, None) => world[d.node],
                (false, Some(instance)) => world[d.node] * instance,
            };
        }
        let joint_matrices: Vec<Vec<Mat4>> = self
            .skins
            .iter()
            .map(|s| {
                s.joints
                    .iter()
                    .zip(&s.inverse_bind)
                    .map(|(&j, ibm)| world[j] * *ibm)
                    .collect()
            })
            .collect();
        for deform in &self.deforms {
            let w = weights[deform.node]
                .as_deref()
                .unwrap_or(&self.nodes[deform.node].rest_weights);
            let joints = deform
                .skin
                .as_ref()
                .map(|(s, inf)| (&joint_matrices[*s][..], inf));
            deform.apply(w, joints, &world[deform.node], scene);
        }
        self.place_cameras_and_lights(&world, scene);
        Ok(())
    }

    /// Checks that the scene has every mesh and draw that the rig rewrites, with the vertex
    /// counts it had when loaded.
    fn check(&self, scene: &Scene) -> Result<(), PoseError> {
        if let Some(d) = self.draws.iter().find(|d| d.draw >= scene.draws.len()) {
            return Err(PoseError::Mismatch(format!(
                "draw {} of {}",
                d.draw,
                scene.draws.len()
            )));
        }
        for deform in &self.deforms {
            let expected = deform
                .corners
                .as_ref()
                .map_or(deform.positions.len(), Vec::len);
            let mesh = scene.meshes.get(deform.mesh).ok_or_else(|| {
                PoseError::Mismatch(format!("mesh {} of {}", deform.mesh, scene.meshes.len()))
            })?;
            let normals_ok = mesh.normals.as_ref().map(Vec::len)
                == (deform.normals.is_some() || deform.corners.is_some()).then_some(expected);
            let tangents_ok = match (&mesh.tangents, &deform.tangents) {
                (Some(t), Some(_)) => t.len() == expected && deform.corners.is_none(),
                (Some(_), None) | (None, Some(_)) => false,
                (None, None) => true,
            };
            if mesh.positions.len() != expected || !normals_ok || !tangents_ok {
                return Err(PoseError::Mismatch(format!(
                    "mesh {} has {} vertices, not {expected}",
                    deform.mesh,
                    mesh.positions.len()
                )));
            }
        }
        Ok(())
    }

    /// Moves the file's cameras and lights with their nodes. The scene's camera follows when
    /// it is still the file camera it was loaded as.
    fn place_cameras_and_lights(&self, world: &[Mat4], scene: &mut Scene) {
        for &(index, node) in &self.cameras {
            let view = world[node].inverse();
            let Some(named) = scene.file_cameras.get_mut(index) else {
                continue;
            };
            if !view.is_finite() {
                continue;
            }
            if scene.camera == named.camera {
                scene.camera.view = view;
            }
            named.camera.view = view;
        }
        for &(index, node) in &self.lights {
            let Some(light) = scene.lights.get_mut(index) else {
                continue;
            };
            let position = world[node].transform_point3(Vec3::ZERO);
            let direction = world[node]
                .transform_vector3(Vec3::NEG_Z)
                .normalize_or_zero();
            if position.is_finite() {
                light.position = position;
                light.direction = direction;
            }
        }
        if let (Some(node), Light::Directional { to_light, .. }) =
            (self.directional, &mut scene.light)
        {
            *to_light = world[node].transform_vector3(Vec3::Z).normalize_or_zero();
        }
    }
}

impl Deform {
    /// Morphs with `weights`, skins with `joints` (joint matrices and influences) when given,
    /// and writes the result into the scene's mesh (checked by [`Rig::check`]).
    fn apply(
        &self,
        weights: &[f32],
        joints: Option<(&[Mat4], &Influences)>,
        node_world: &Mat4,
        scene: &mut Scene,
    ) {
        let mut positions = self.positions.clone();
        let mut normals = self.normals.clone();
        let mut tangents = self.tangents.clone();
        for (target, &weight) in self.targets.iter().zip(weights) {
            if !morph::applies(weight) {
                continue;
            }
            if let Some(deltas) = &target.positions {
                morph::add_target(&mut positions, deltas, weight);
            }
            if let (Some(deltas), Some(normals)) = (&target.normals, normals.as_mut()) {
                morph::add_target(normals, deltas, weight);
            }
            if let (Some(deltas), Some(tangents)) = (&target.tangents, tangents.as_mut()) {
                let mut directions: Vec<Vec3> = tangents.iter().map(|t| t.truncate()).collect();
                morph::add_target(&mut directions, deltas, weight);
                for (t, d) in tangents.iter_mut().zip(directions) {
                    *t = d.extend(t.w);
                }
            }
        }
        if let Some((matrices, influences)) = joints {
            let mut skinned = skin::Skinned {
                positions: positions.clone(),
                normals: normals.clone(),
                tangents: tangents.clone(),
            };
            skin::skin(
                influences,
                matrices,
                node_world,
                &positions,
                normals.as_deref(),
                tangents.as_deref(),
                &mut skinned,
            );
            positions = skinned.positions;
            normals = skinned.normals;
            tangents = skinned.tangents;
        }
        let mesh = &mut scene.meshes[self.mesh];
        match &self.corners {
            None => {
                mesh.positions.copy_from_slice(&positions);
                if let (Some(dst), Some(src)) = (mesh.normals.as_mut(), normals) {
                    dst.copy_from_slice(&src);
                }
                if let (Some(dst), Some(src)) = (mesh.tangents.as_mut(), tangents) {
                    dst.copy_from_slice(&src);
                }
            }
            Some(corners) => {
                let get = |i: u32| positions.get(i as usize).copied().unwrap_or(Vec3::NAN);
                let Some(out_normals) = mesh.normals.as_mut() else {
                    return;
                };
                for (t, tri) in corners.chunks_exact(3).enumerate() {
                    let [a, b, c] = [get(tri[0]), get(tri[1]), get(tri[2])];
                    // As `Mesh::flat_shaded` computes it.
                    let normal = (b - a).cross(c - a).try_normalize().unwrap_or(Vec3::Z);
                    for (k, p) in [a, b, c].into_iter().enumerate() {
                        mesh.positions[3 * t + k] = p;
                        out_normals[3 * t + k] = normal;
                    }
                }
            }
        }
    }
}

/// Poses a loaded glTF scene at any time of the animation chosen when it was loaded
/// ([`crate::LoadOptions::animation`]), without reloading the file.
///
/// [`AnimationPlayer::pose`] sets, from the animated node transforms and morph weights at that
/// time: every draw's model matrix, the positions and normals of skinned and morphed meshes, the
/// file cameras' views (and the scene's camera while it is the file camera it was loaded
/// with) and the lights' placement. Nothing else of the scene changes: a camera made up to frame
/// the scene (the file has none) keeps framing the pose the file was loaded at. Posing
/// allocates only scratch space of the size of the deformed meshes, and gives the same bits for
/// the same time: a scene loaded at time `t` equals one loaded at any time and posed at `t`
/// (but for such a made-up camera).
#[derive(Clone, Debug)]
pub struct AnimationPlayer {
    rig: Rig,
    clip: Clip,
}

impl AnimationPlayer {
    /// A player of `clip` over the loaded scene described by `rig`.
    pub(crate) fn new(rig: Rig, clip: Clip) -> Self {
        Self { rig, clip }
    }

    /// The animation's index in the file.
    pub fn index(&self) -> usize {
        self.clip.index
    }

    /// The animation's name (`animation N` when the file gives none).
    pub fn name(&self) -> &str {
        &self.clip.name
    }

    /// The earliest and latest key times of the animation's channels, in seconds; `(0, 0)` when
    /// it animates nothing that is drawn. Times outside hold the first or last keys.
    pub fn time_range(&self) -> (f32, f32) {
        self.clip.time_range()
    }

    /// Poses `scene` (the scene this player was loaded with) at `time` seconds. An error when
    /// the time is not finite or the scene's meshes and draws are not those it was loaded with;
    /// the scene is unchanged then.
    pub fn pose(&self, scene: &mut Scene, time: f32) -> Result<(), PoseError> {
        self.rig.pose(Some(&self.clip), time, scene)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn node(parent: Option<usize>) -> RigNode {
        RigNode {
            parent,
            rest_matrix: Mat4::IDENTITY,
            rest_trs: (Vec3::ZERO, Quat::IDENTITY, Vec3::ONE),
            rest_weights: Vec::new(),
        }
    }

    #[test]
    fn nodes_are_ordered_after_their_parents_and_loops_are_cut() {
        let mut rig = Rig {
            nodes: vec![
                node(Some(2)),
                node(None),
                node(Some(1)),
                node(Some(4)),
                node(Some(3)),
            ],
            ..Rig::default()
        };
        rig.sort();
        let at = |i: usize| rig.order.iter().position(|&n| n == i).unwrap();
        assert_eq!(rig.order.len(), 5);
        assert!(at(1) < at(2) && at(2) < at(0));
        // 3 and 4 point at each other: one of them became a root.
        assert!(rig.nodes[3].parent.is_none() || rig.nodes[4].parent.is_none());
        assert!(at(3) != at(4));
    }
}
