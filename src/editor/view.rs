//! The view both the window and the headless renderer need besides the core: the stage,
//! the scene built from documents (startup, Open, undo/redo applied in place), the skin
//! material and the drawing of skeletons.

use bevy::prelude::*;

use super::camera::{OrbitCamera, apply_orbit_camera};
use super::document::{
    AssetLibrary, LiveCharacters, NextCharacterId, PendingScene, SceneCharacter, spawn_from_doc, startup_doc,
};
use super::stage::{StageSettings, apply_stage_settings, draw_grid_and_axes, spawn_stage};
use super::state::{Messages, Selection, StartupEdits, StartupPaths, UnloadedCharacters};
use super::{draw, history, ik_drag};
use crate::formats::scene::DisplayDoc;
use crate::scene::{Character, DisplayMode, MarionetteSystems, SkinMesh, SkinView};

/// One material for every skin: white, so vertex colours (tint or weights) show as they are.
#[derive(Resource)]
pub struct SkinMaterial(pub Handle<StandardMaterial>);

/// Stage, scene document and drawing: everything both the window and the headless
/// renderer need besides the core.
pub struct ViewPlugin;

impl Plugin for ViewPlugin {
    fn build(&self, app: &mut App) {
        draw::setup_skeleton_gizmos(app);
        app.init_resource::<StageSettings>()
            .init_resource::<Messages>()
            .init_resource::<StartupPaths>()
            .init_resource::<StartupEdits>()
            .init_resource::<Selection>()
            .init_resource::<UnloadedCharacters>()
            .init_resource::<AssetLibrary>()
            .init_resource::<PendingScene>()
            .init_resource::<NextCharacterId>()
            .add_plugins((crate::scene::smpl::SmplPlugin, super::readiness::ReadinessPlugin))
            .add_systems(Startup, (setup_skin_material, spawn_stage, queue_startup_scene).chain())
            .add_systems(
                PostUpdate,
                (apply_pending_scene, sync_character_views)
                    .chain()
                    .in_set(MarionetteSystems::Animate)
                    .before(crate::scene::smpl::SmplPlayback),
            )
            .add_systems(
                PostUpdate,
                (
                    attach_skin_material,
                    apply_display_mode,
                    apply_stage_settings,
                    apply_orbit_camera,
                    draw::draw_skeletons,
                    draw_grid_and_axes,
                )
                    .in_set(MarionetteSystems::Draw),
            );
    }
}

fn setup_skin_material(mut commands: Commands, mut materials: ResMut<Assets<StandardMaterial>>) {
    let material =
        materials.add(StandardMaterial { base_color: Color::WHITE, perceptual_roughness: 0.75, ..default() });
    commands.insert_resource(SkinMaterial(material));
}

/// Turns the startup paths into the first scene (writes `PendingScene`, `Messages`).
fn queue_startup_scene(
    paths: Res<StartupPaths>,
    edits: Res<StartupEdits>,
    mut library: ResMut<AssetLibrary>,
    mut messages: ResMut<Messages>,
    mut pending: ResMut<PendingScene>,
) {
    let mut notes = Vec::new();
    let doc = startup_doc(&paths.0, &mut library, &mut notes);
    notes.into_iter().for_each(|m| messages.push(m));
    if let Some(mut doc) = doc {
        apply_startup_edits(&mut doc, &edits, &mut library, &mut messages);
        pending.frame = doc.camera.is_none();
        pending.with_camera = true;
        pending.doc = Some(doc);
    }
}

/// Applies `--pose` and `--ik` to every character of `doc` that has the joints.
fn apply_startup_edits(
    doc: &mut crate::formats::scene::SceneDoc,
    edits: &StartupEdits,
    library: &mut AssetLibrary,
    messages: &mut Messages,
) {
    use crate::formats::scene::pose_key;
    if edits.poses.is_empty() && edits.ik.is_empty() {
        return;
    }
    for c in &mut doc.characters {
        let Ok(asset) = library.load(&c.source) else { continue };
        let skeleton = &asset.skeleton;
        let (mut pose, _) = super::document::pose_from_doc(&asset, c);
        let poses: Vec<_> = edits.poses.iter().filter(|p| skeleton.resolve(&p.joint).is_some()).cloned().collect();
        let ik: Vec<_> = edits.ik.iter().filter(|p| skeleton.resolve(&p.joint).is_some()).cloned().collect();
        let _ = crate::cli::posing::apply_pose_specs(skeleton, &mut pose, &poses);
        if let Ok(reports) = crate::cli::posing::apply_ik_specs(skeleton, &mut pose, c.placement.to_mat4(), &ik) {
            reports
                .iter()
                .for_each(|r| messages.push(format!("{}: {}", c.name, crate::cli::posing::describe_ik(skeleton, r))));
        }
        let initial = skeleton.initial_pose();
        c.pose =
            (0..skeleton.len()).filter(|&j| pose[j] != initial[j]).map(|j| (pose_key(skeleton, j), pose[j])).collect();
    }
}

/// Builds the pending document: characters that stay (same id, source and weights; not on
/// Open) are set in place, the others spawned, those no longer listed despawned; sets camera
/// and stage when asked; frames the characters when the document has no camera (reads
/// `PendingScene`; writes entities, `OrbitCamera`, `StageSettings`, `Messages`).
#[allow(clippy::too_many_arguments)]
pub fn apply_pending_scene(
    mut commands: Commands,
    mut pending: ResMut<PendingScene>,
    mut meshes: ResMut<Assets<Mesh>>,
    mut library: ResMut<AssetLibrary>,
    mut ids: ResMut<NextCharacterId>,
    mut messages: ResMut<Messages>,
    mut stage: ResMut<StageSettings>,
    mut live: LiveCharacters,
    mut cameras: Query<&mut OrbitCamera>,
    mut reset: SceneReset,
) {
    let Some(doc) = pending.doc.take() else {
        return;
    };
    if pending.with_camera {
        // A new scene (Open, startup): nothing selected, pinned or undoable refers to it.
        reset.clear();
    }
    reset.unloaded.0.clear();
    // Undo, redo and rebind keep the characters that stay (same id, source and weights):
    // they are set in place. A new scene (Open) replaces everything.
    let live_index = if pending.with_camera { Vec::new() } else { live.index() };
    let mut kept = std::collections::HashSet::new();
    let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    let ids_of_doc = stable_ids(&doc.characters, &mut ids);
    for (c, id) in doc.characters.iter().zip(ids_of_doc) {
        let same =
            live_index.iter().find(|(_, i, source, binding)| *i == id && *source == c.source && *binding == c.binding);
        let spawned = match same {
            Some(&(entity, ..)) => {
                kept.insert(entity);
                Ok(live.update_from_doc(entity, c))
            }
            None => spawn_from_doc(&mut commands, &mut meshes, &mut library, c, id).map(|(_, notes)| notes),
        };
        match spawned {
            Ok(notes) => {
                notes.into_iter().for_each(|m| messages.push(m));
                if let Ok(asset) = library.load(&c.source) {
                    let (a, b) = asset.bounds();
                    let m = c.placement.to_mat4();
                    for corner in [a, b, Vec3::new(a.x, b.y, a.z), Vec3::new(b.x, a.y, b.z)] {
                        lo = lo.min(m.transform_point3(corner));
                        hi = hi.max(m.transform_point3(corner));
                    }
                }
            }
            Err(e) => {
                messages.push(format!("{e} (`{}` is kept in the scene file as it was)", c.name));
                reset.unloaded.0.push(c.clone());
            }
        }
    }
    for (entity, character, ..) in &live.characters {
        if !kept.contains(&entity) {
            crate::scene::despawn_character(&mut commands, entity, character);
        }
    }
    if pending.with_camera {
        stage.0 = doc.stage;
        for mut orbit in &mut cameras {
            if let Some(c) = doc.camera {
                *orbit = OrbitCamera(c);
            } else if pending.frame && lo.x <= hi.x {
                *orbit = OrbitCamera::framing(lo, hi);
            }
        }
    }
}

/// The id each character of a document gets: its own (saved in the scene, kept by undo
/// and redo, so selections and pins stay valid), or a fresh one where it has none or
/// repeats one already taken.
fn stable_ids(characters: &[crate::formats::scene::CharacterDoc], next: &mut NextCharacterId) -> Vec<u64> {
    next.0 = characters.iter().filter_map(|c| c.id).fold(next.0, u64::max);
    let mut taken = std::collections::HashSet::new();
    characters.iter().map(|c| c.id.filter(|&id| taken.insert(id)).unwrap_or_else(|| next.take())).collect()
}

/// What a newly opened scene resets: the selection, the pins, the history, the characters
/// that did not load.
#[derive(bevy::ecs::system::SystemParam)]
pub struct SceneReset<'w> {
    selection: ResMut<'w, Selection>,
    pins: Option<ResMut<'w, ik_drag::Pins>>,
    history: Option<ResMut<'w, history::History>>,
    unloaded: ResMut<'w, UnloadedCharacters>,
}

impl SceneReset<'_> {
    fn clear(&mut self) {
        *self.selection = Selection::default();
        if let Some(pins) = &mut self.pins {
            pins.0.clear();
        }
        if let Some(history) = &mut self.history {
            **history = history::History::default();
        }
    }
}

/// Keeps each character's colouring in step with its options and the selection (reads
/// `SceneCharacter`, `Selection`; writes `SkinView`, `Visibility`).
fn sync_character_views(
    selection: Res<Selection>,
    mut characters: Query<(&SceneCharacter, &mut SkinView, &mut Visibility)>,
) {
    for (sc, mut view, mut visibility) in &mut characters {
        let heat = (sc.heat_of_selected && selection.character == Some(sc.id))
            .then(|| selection.joints.first().copied())
            .flatten();
        if view.heat_joint != heat {
            view.heat_joint = heat;
        }
        let wanted = if sc.visible { Visibility::Inherited } else { Visibility::Hidden };
        visibility.set_if_neq(wanted);
    }
}

/// Gives new skin meshes the shared material (writes `MeshMaterial3d`).
fn attach_skin_material(
    mut commands: Commands,
    material: Res<SkinMaterial>,
    new_skins: Query<Entity, Added<SkinMesh>>,
) {
    for entity in &new_skins {
        commands.entity(entity).insert(MeshMaterial3d(material.0.clone()));
    }
}

/// Shows or hides skins by display mode (reads `DisplayMode`; writes skin `Visibility`).
fn apply_display_mode(
    characters: Query<(&Character, &DisplayMode), Changed<DisplayMode>>,
    mut visibility: Query<&mut Visibility, With<SkinMesh>>,
) {
    for (character, mode) in &characters {
        if let Ok(mut v) = visibility.get_mut(character.skin_entity) {
            *v = if **mode == DisplayDoc::Skeleton { Visibility::Hidden } else { Visibility::Inherited };
        }
    }
}
