//! The view both the window and the headless renderer need besides the core: the stage,
//! the scene opened from a document (startup, Open), each character's view kept in step
//! with its options, the skin material and the drawing of skeletons.

use bevy::prelude::*;

use crate::document::AssetLibrary;
use crate::document::scenes::{scene_path, startup_doc};
use crate::editor::edits::history;
use crate::editor::present::draw;
use crate::editor::present::skin_material::{self, SkinAttributeStore, SkinMaterial, SkinMaterialAsset, SkinTextures};
use crate::editor::present::stage::{
    DrawnStage, apply_stage_settings, draw_axes, draw_grids, fit_shadows_to_camera, fit_stage_to_scene, spawn_stage,
    stage_the_settings,
};
use crate::editor::scene_doc::document::{Library, NextCharacterId, PendingScene, SceneCharacter, spawn_from_doc};
use crate::editor::state::StageSettings;
use crate::editor::state::camera::{FramingAspect, OrbitCamera, apply_orbit_camera};
use crate::editor::state::{Messages, Selection, StartupEdits, StartupPaths, UnloadedCharacters};
use crate::formats::scene::{CameraDoc, CharacterId, DisplayDoc};
use crate::rig::SkinTexture;
use crate::scene::Slot;
use crate::scene::handoff::SkinAttributes;
use crate::scene::{Character, CharacterView, HeatJoint, SkinMesh};
use bevy::mesh::MeshTag;
use bevy::render::storage::ShaderBuffer;

/// The live scene without drawing: opening documents, edits and their history, SMPL
/// playback, each character's view in step with its options (used by the window, the
/// headless renderer and the tests).
pub struct ScenePlugin;

impl Plugin for ScenePlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<StageSettings>()
            .init_resource::<crate::editor::state::ShotSettings>()
            .init_resource::<crate::editor::state::camera::Bookmarks>()
            .init_resource::<crate::editor::state::camera::CameraRequest>()
            .init_resource::<Messages>()
            .init_resource::<Selection>()
            .init_resource::<UnloadedCharacters>()
            .init_resource::<PendingScene>()
            .init_resource::<crate::editor::scene_doc::document::ChangedAtStartup>()
            .init_resource::<crate::editor::state::SavedState>()
            .init_resource::<crate::editor::state::Pins>()
            .init_resource::<Library>()
            .init_resource::<FramingAspect>()
            .init_resource::<FramingView>()
            .init_resource::<crate::editor::scene_doc::arrange::ArrangeWhenSkinned>()
            .init_resource::<crate::editor::state::PoseLibrary>()
            .init_resource::<GhostMaterials>()
            .add_plugins((crate::scene::PlaybackPlugin, crate::editor::edits::commands::CommandsPlugin))
            .add_systems(
                PostUpdate,
                (
                    (apply_pending_scene, mark_skins_of_slots)
                        .chain()
                        .in_set(crate::editor::order::EditorSystems::OpenScene),
                    (
                        sync_character_views,
                        crate::editor::scene_doc::document::update_humanoid_maps,
                        crate::editor::scene_doc::retarget::resolve_retargets
                            .run_if(any_with_component::<crate::scene::keyframes::ClipPlayer>),
                    )
                        .chain()
                        .in_set(crate::editor::order::EditorSystems::SyncViews),
                ),
            )
            .add_systems(
                PostUpdate,
                (
                    crate::editor::scene_doc::arrange::arrange_when_skinned,
                    crate::editor::scene_doc::attach::follow_holders,
                )
                    .chain()
                    .in_set(crate::editor::order::EditorSystems::Arrange),
            );
    }
}

/// The scene with its stage and drawing: everything both the window and the headless
/// renderer need besides the core; opens what the command line named at startup.
pub struct ViewPlugin;

impl Plugin for ViewPlugin {
    fn build(&self, app: &mut App) {
        draw::setup_skeleton_gizmos(app);
        app.init_resource::<StartupPaths>()
            .init_resource::<StartupEdits>()
            .add_plugins((ScenePlugin, crate::editor::present::readiness::ReadinessPlugin))
            .add_plugins(crate::editor::present::skin_material::SkinMaterialPlugin)
            .add_systems(Startup, (spawn_stage, queue_startup_scene).chain())
            .add_systems(
                PostUpdate,
                (
                    attach_skin_material,
                    store_skin_attributes,
                    choose_skin_material,
                    apply_display_mode,
                    stage_the_settings,
                    apply_stage_settings,
                    frame_when_skinned,
                    apply_orbit_camera,
                    draw::draw_skeletons,
                    fit_stage_to_scene,
                    fit_shadows_to_camera,
                    draw_grids,
                    draw_axes,
                )
                    .chain()
                    .in_set(crate::editor::order::EditorSystems::Present),
            );
    }
}

/// Turns the startup paths into the first scene (writes `PendingScene`, `Messages`, and
/// whether the startup options changed it).
#[allow(clippy::too_many_arguments)]
fn queue_startup_scene(
    paths: Res<StartupPaths>,
    edits: Res<StartupEdits>,
    mut library: ResMut<Library>,
    mut messages: ResMut<Messages>,
    mut pending: ResMut<PendingScene>,
    mut arrange: ResMut<crate::editor::scene_doc::arrange::ArrangeWhenSkinned>,
    mut framing: ResMut<FramingView>,
    mut changed: ResMut<crate::editor::scene_doc::document::ChangedAtStartup>,
) {
    let mut notes = Vec::new();
    let before = startup_doc(&paths.0, &mut library, &mut notes);
    let mut doc = before.clone();
    if let Some(opened) = &mut doc {
        match apply_startup_options(opened, &paths.0, &edits, &mut library) {
            Ok(said) => notes.extend(said),
            Err(e) => {
                notes.push(e);
                doc.clone_from(&before);
            }
        }
    }
    // A fitted character stays where its camera sees it.
    let fitted = edits.pose.fit.is_some() || edits.pose.fit_sequence.is_some();
    *arrange = crate::editor::scene_doc::arrange::ArrangeWhenSkinned {
        side_by_side: !paths.0.is_empty() && scene_path(&paths.0).is_none() && !fitted,
        match_height: edits.match_height,
    };
    notes.into_iter().for_each(|m| messages.push(m));
    if let Some(mut doc) = doc {
        changed.0 = Some(&doc) != before.as_ref() || edits.recovered;
        if let Some(view) = startup_view(&mut doc, edits.view, edits.ortho) {
            framing.0 = view;
        }
        *pending = PendingScene { frame: doc.camera.is_none(), doc: Some(doc) };
    }
}

/// The view and lens `--view` and `--ortho` ask for (from the scene's camera, else the
/// three-quarter view), which the characters are then framed from: the scene's own camera
/// is left out. None when neither is asked for.
pub fn startup_view(
    doc: &mut crate::formats::scene::SceneDoc,
    view: Option<crate::formats::scene::ViewName>,
    ortho: bool,
) -> Option<CameraDoc> {
    if view.is_none() && !ortho {
        return None;
    }
    let mut framing = doc.camera.take().unwrap_or(FramingView::default().0);
    if let Some(name) = view {
        framing = framing.looking_from(name);
    }
    if ortho && framing.ortho.is_none() {
        framing = framing.toggled_ortho();
    }
    Some(framing)
}

/// The scene the app opens with: the startup paths as a document (the default scene when
/// there are none) with the command line's options applied as every command applies them
/// ([`crate::document::options`]; character files posed in their files' space, then
/// placed side by side) and `--transparent`. Returns the notes (IK reports), or
/// what an option named that no character has.
pub fn startup_scene(
    paths: &[std::path::PathBuf],
    edits: &StartupEdits,
    library: &mut AssetLibrary,
    notes: &mut Vec<String>,
) -> Result<Option<crate::formats::scene::SceneDoc>, String> {
    let Some(mut doc) = startup_doc(paths, library, notes) else { return Ok(None) };
    notes.extend(apply_startup_options(&mut doc, paths, edits, library)?);
    Ok(Some(doc))
}

/// The command line's options on the opened document (see [`startup_scene`]).
fn apply_startup_options(
    doc: &mut crate::formats::scene::SceneDoc,
    paths: &[std::path::PathBuf],
    edits: &StartupEdits,
    library: &mut AssetLibrary,
) -> Result<Vec<String>, String> {
    // Character files are posed where their files put them (so `--ik` targets are in the
    // file's space, as `export` reads them), then stood where the layout puts them; a fit
    // is made where the layout puts them (its camera sees them there).
    let fitting = edits.pose.fit.is_some() || edits.pose.fit_sequence.is_some();
    let layout: Option<Vec<_>> = (scene_path(paths).is_none() && !fitting)
        .then(|| doc.characters.iter_mut().map(|c| std::mem::take(&mut c.placement)).collect());
    let notes =
        crate::document::options::apply_options(doc, &edits.pose_options(), library).map_err(|e| e.to_string())?;
    for (c, placed) in doc.characters.iter_mut().zip(layout.iter().flatten()) {
        c.placement = crate::formats::scene::PlacementDoc::from_mat4(placed.to_mat4() * c.placement.to_mat4());
    }
    if edits.transparent {
        doc.stage.background = crate::formats::scene::BackgroundDoc::Transparent;
        doc.stage.floor = false;
    }
    Ok(notes)
}

/// Opens the pending document in place of the current scene: every character is
/// replaced, camera and stage set, selection, pins and history cleared; and each scene
/// waiting on another slot's camera in place of that slot's ([`SlotOpening::open`]) (reads
/// `PendingScene`, `SceneToOpen`; writes entities, `OrbitCamera`, `StageSettings`,
/// `DrawnStage`, `Messages`).
#[allow(clippy::too_many_arguments)]
pub fn apply_pending_scene(
    mut commands: Commands,
    mut pending: ResMut<PendingScene>,
    mut meshes: ResMut<Assets<Mesh>>,
    mut library: ResMut<Library>,
    mut ids: ResMut<NextCharacterId>,
    mut messages: ResMut<Messages>,
    mut stage: ResMut<StageSettings>,
    live: Query<(Entity, &Character, &Slot)>,
    mut cameras: Query<(Entity, &Slot, &mut OrbitCamera, Option<&mut DrawnStage>, Option<&mut SceneToOpen>)>,
    mut reset: SceneReset,
) {
    let mut opening =
        SlotOpening { commands: &mut commands, meshes: &mut meshes, library: &mut library, ids: &mut ids };
    if let Some(doc) = pending.doc.take() {
        reset.clear();
        let camera = cameras.iter_mut().find(|c| *c.1 == Slot(0)).map(|(camera, _, orbit, ..)| (camera, orbit));
        let frame = pending.frame && doc.camera.is_none();
        reset.unloaded.0 = opening.open(&doc, Slot(0), camera, &live, frame, &mut messages);
        stage.0 = doc.stage;
        reset.pose_library.0 = doc.poses;
        reset.shot.0 = doc.shot;
        reset.bookmarks.0 = doc.bookmarks;
    }
    for (camera, &slot, orbit, drawn, to_open) in &mut cameras {
        let (Some(doc), Some(mut drawn)) = (to_open.and_then(|mut o| o.0.take()), drawn) else { continue };
        opening.open(&doc, slot, Some((camera, orbit)), &live, doc.camera.is_none(), &mut messages);
        drawn.set_if_neq(DrawnStage(doc.stage));
    }
}

/// A scene to open in a slot other than the editor's, on that slot's camera (a data set's
/// render draws several scenes a frame).
#[derive(Component, Default)]
pub struct SceneToOpen(pub Option<Box<crate::formats::scene::SceneDoc>>);

/// What opening a scene in a slot writes.
struct SlotOpening<'a, 'w, 's> {
    commands: &'a mut Commands<'w, 's>,
    meshes: &'a mut Assets<Mesh>,
    library: &'a mut Library,
    ids: &'a mut NextCharacterId,
}

impl SlotOpening<'_, '_, '_> {
    /// Replaces the slot's characters with the document's and sets its camera (framed once
    /// they are skinned, where `frame`); returns the characters that did not load.
    fn open(
        &mut self,
        doc: &crate::formats::scene::SceneDoc,
        slot: Slot,
        camera: Option<(Entity, Mut<OrbitCamera>)>,
        live: &Query<(Entity, &Character, &Slot)>,
        frame: bool,
        messages: &mut Messages,
    ) -> Vec<crate::formats::scene::CharacterDoc> {
        for (entity, character, _) in live.iter().filter(|c| *c.2 == slot) {
            crate::scene::despawn_character(self.commands, entity, character);
        }
        let mut unloaded = Vec::new();
        for (c, id) in doc.characters.iter().zip(stable_ids(&doc.characters, self.ids)) {
            match spawn_from_doc(self.commands, self.meshes, self.library, c, id) {
                Ok((entity, notes)) => {
                    self.commands.entity(entity).insert(slot.marks());
                    notes.into_iter().for_each(|m| messages.push(m));
                }
                Err(e) => {
                    messages.push(format!("{e} (`{}` is kept in the scene file as it was)", c.name));
                    unloaded.push(c.clone());
                }
            }
        }
        if let Some((camera, mut orbit)) = camera {
            if let Some(c) = doc.camera {
                *orbit = OrbitCamera(c);
            }
            match frame {
                true => self.commands.entity(camera).insert(FrameWhenSkinned),
                false => self.commands.entity(camera).remove::<FrameWhenSkinned>(),
            };
        }
        unloaded
    }
}

/// Puts each new skin on its character's slot's layer (reads `Slot`; writes the skin's
/// `RenderLayers`).
fn mark_skins_of_slots(
    mut commands: Commands,
    skins: Query<(Entity, &SkinMesh), Added<SkinMesh>>,
    slots: Query<&Slot>,
) {
    for (skin, of) in &skins {
        if let Ok(&slot) = slots.get(of.character) {
            commands.entity(skin).insert(slot.marks());
        }
    }
}

/// Asks a slot's camera to frame the slot's characters once they are skinned.
#[derive(Component)]
pub struct FrameWhenSkinned;

/// The direction and lens framing starts from (the three-quarter view unless `--view` or
/// `--ortho` said otherwise).
#[derive(Resource, Clone, Copy, Debug)]
pub struct FramingView(pub CameraDoc);

impl Default for FramingView {
    fn default() -> Self {
        Self(CameraDoc::default().looking_from(crate::formats::scene::ViewName::ThreeQuarter))
    }
}

/// Frames each slot's characters as they stand, posed (their skinned vertices, placed),
/// once all are skinned after a scene opened (reads `SkinScratch`; writes `OrbitCamera`).
pub fn frame_when_skinned(
    mut commands: Commands,
    characters: Query<(&crate::scene::Placement, &crate::scene::SkinScratch, &crate::scene::PoseDirty, &Slot)>,
    aspect: Res<FramingAspect>,
    view: Res<FramingView>,
    mut cameras: Query<(Entity, &Slot, &mut OrbitCamera), With<FrameWhenSkinned>>,
) {
    for (camera, slot, mut orbit) in &mut cameras {
        let slot_characters = || characters.iter().filter(move |c| c.3 == slot);
        if slot_characters().any(|c| *c.2 != crate::scene::PoseDirty::default()) {
            continue;
        }
        commands.entity(camera).remove::<FrameWhenSkinned>();
        let points = slot_characters().flat_map(|(placement, scratch, ..)| {
            let m = placement.to_mat4();
            scratch.positions.iter().map(move |&p| m.transform_point3(p))
        });
        if points.clone().next().is_some() {
            *orbit = OrbitCamera::framing_from(points, aspect.0, view.0);
        }
    }
}

/// The id each character of a document gets: its own (saved in the scene, kept by undo
/// and redo, so selections and pins stay valid), or a fresh one where it has none or
/// repeats one already taken.
fn stable_ids(characters: &[crate::formats::scene::CharacterDoc], next: &mut NextCharacterId) -> Vec<CharacterId> {
    next.0 = characters.iter().filter_map(|c| c.id).map(|id| id.0).fold(next.0, u64::max);
    let mut taken = std::collections::HashSet::new();
    characters.iter().map(|c| c.id.filter(|&id| taken.insert(id)).unwrap_or_else(|| next.take())).collect()
}

/// What a newly opened scene resets: the selection, the pins, the history, the characters
/// that did not load.
#[derive(bevy::ecs::system::SystemParam)]
pub struct SceneReset<'w> {
    selection: ResMut<'w, Selection>,
    pins: ResMut<'w, crate::editor::state::Pins>,
    history: ResMut<'w, history::History>,
    unloaded: ResMut<'w, UnloadedCharacters>,
    pose_library: ResMut<'w, crate::editor::state::PoseLibrary>,
    shot: ResMut<'w, crate::editor::state::ShotSettings>,
    bookmarks: ResMut<'w, crate::editor::state::camera::Bookmarks>,
    saved: ResMut<'w, crate::editor::state::SavedState>,
    changed_at_startup: ResMut<'w, crate::editor::scene_doc::document::ChangedAtStartup>,
}

impl SceneReset<'_> {
    fn clear(&mut self) {
        *self.selection = Selection::default();
        self.unloaded.0.clear();
        self.pins.0.clear();
        *self.history = history::History::default();
        let changed_at_start = std::mem::take(&mut self.changed_at_startup.0);
        *self.saved = crate::editor::state::SavedState { changed_at_start, ..Default::default() };
    }
}

/// Keeps each character's heat joint and visibility in step with its view options and
/// the selection (reads `CharacterView`, `Selection`; writes `HeatJoint`, `Visibility`).
pub fn sync_character_views(
    selection: Res<Selection>,
    mut characters: Query<(&SceneCharacter, &CharacterView, &mut HeatJoint, &mut Visibility)>,
) {
    for (sc, view, mut heat, mut visibility) in &mut characters {
        let joint = (view.heat_of_selected && selection.character == Some(sc.id))
            .then(|| selection.joints.first().copied())
            .flatten();
        heat.set_if_neq(HeatJoint(joint));
        visibility.set_if_neq(crate::editor::scene_doc::document::visibility_of(view));
    }
}

/// Gives new skin meshes their material: the asset's for their surface (its textures
/// decoded once), or the shared one; both read the skins' attributes from the one buffer
/// (writes `MeshMaterial3d`, `OwnMaterial`).
#[allow(clippy::too_many_arguments)]
fn attach_skin_material(
    mut commands: Commands,
    material: Res<SkinMaterial>,
    store: Res<SkinAttributeStore>,
    mut textures: ResMut<SkinTextures>,
    mut images: ResMut<Assets<Image>>,
    mut materials: ResMut<Assets<SkinMaterialAsset>>,
    mut messages: ResMut<Messages>,
    characters: Query<&Character>,
    new_skins: Query<(Entity, &SkinMesh), Added<SkinMesh>>,
) {
    for (entity, skin) in &new_skins {
        let Ok(character) = characters.get(skin.character) else { continue };
        let own =
            character.skins.get(skin.part).and_then(|p| p.material).and_then(|m| character.asset.materials.get(m));
        let handle = match own {
            Some(m) => {
                let mut image = |texture: &SkinTexture, srgb: bool, sampler| match picture_of(texture) {
                    Ok(picture) => Some(textures.image(texture, &picture, srgb, sampler, &mut images)),
                    Err(e) => {
                        messages.push(format!("{e} (the skin is drawn without it)"));
                        None
                    }
                };
                materials.add(skin_material::skin_material_of(m, store.buffer.clone(), &mut image))
            }
            None => material.0.clone(),
        };
        commands.entity(entity).insert((MeshMaterial3d(handle.clone()), OwnMaterial(handle)));
    }
}

/// A skin mesh's own material, which weight colours and heat maps set aside for the
/// shared one (so that only the vertex colours show).
#[derive(Component)]
pub struct OwnMaterial(pub Handle<SkinMaterialAsset>);

/// Keeps the skins' attributes in the one buffer the skin materials read: when skins come
/// or go, every surface is laid out anew (its place is its mesh's `MeshTag`; when they no
/// longer fit, a larger buffer replaces it in every skin material), else only the
/// recoloured characters' attributes are written, in place: into the main world's copy
/// and, by the render world, the GPU's (reads `Character`, `SkinAttributes`, `SkinMesh`;
/// writes `SkinAttributeStore`, its buffer, `AttributeWrites`, the skin materials,
/// `MeshTag`).
#[allow(clippy::too_many_arguments)]
fn store_skin_attributes(
    mut commands: Commands,
    mut store: ResMut<SkinAttributeStore>,
    mut in_place: ResMut<skin_material::AttributeWrites>,
    mut buffers: ResMut<Assets<ShaderBuffer>>,
    mut materials: ResMut<Assets<SkinMaterialAsset>>,
    characters: Query<(&Character, Ref<SkinAttributes>)>,
    tags: Query<Option<&MeshTag>, With<SkinMesh>>,
    added: Query<(), Added<SkinMesh>>,
    mut removed: RemovedComponents<SkinMesh>,
) {
    let relaid = !added.is_empty() || removed.read().count() > 0;
    if relaid {
        let mut surfaces: Vec<(Entity, u32)> =
            characters.iter().flat_map(|(c, _)| c.skins.iter().map(|p| (p.entity, p.vertices.len() as u32))).collect();
        surfaces.sort_unstable();
        if store.lay_out(&surfaces) {
            // A new asset (and GPU buffer) that each material binds once it is prepared.
            store.buffer = buffers.add(store.empty_buffer());
            for (_, material) in materials.iter_mut() {
                material.extension.attributes = store.buffer.clone();
            }
        }
        for (entity, _) in surfaces {
            let first = store.first(entity);
            if let (Ok(tag), Some(first)) = (tags.get(entity), first)
                && tag.is_none_or(|t| t.0 != first)
            {
                commands.entity(entity).insert(MeshTag(first));
            }
        }
    }
    in_place.writes.clear();
    let mut written = characters.iter().filter(|(_, attributes)| relaid || attributes.is_changed()).peekable();
    if written.peek().is_none() {
        return;
    }
    let surfaces = written.flat_map(|(character, attributes)| {
        let attributes = attributes.into_inner();
        character.skins.iter().map(move |part| (part.entity, &part.vertices, attributes))
    });
    if relaid {
        // The whole buffer goes to the GPU: every surface has a new place.
        let Some(mut buffer) = buffers.get_mut(&store.buffer) else { return };
        for (entity, vertices, attributes) in surfaces {
            store.write(&mut buffer, entity, attributes, vertices);
        }
        return;
    }
    // Only the recoloured surfaces go, written in place by the render world.
    let Some(buffer) = buffers.get_mut_untracked(&store.buffer) else { return };
    in_place.buffer = store.buffer.id();
    for (entity, vertices, attributes) in surfaces {
        if let Some((at, bytes)) = store.write(buffer, entity, attributes, vertices) {
            in_place.writes.push((at, bytes.to_vec()));
        }
    }
}

/// Draws skins in the shared material while they show weights or heat, else in their own;
/// a ghost (opacity below 1) in a see-through copy of that (reads `CharacterView`,
/// `HeatJoint`; writes `MeshMaterial3d`, `GhostMaterials`).
fn choose_skin_material(
    characters: Query<(&Character, &CharacterView, &HeatJoint), Or<(Changed<CharacterView>, Changed<HeatJoint>)>>,
    material: Res<SkinMaterial>,
    mut ghosts: ResMut<GhostMaterials>,
    mut materials: ResMut<Assets<SkinMaterialAsset>>,
    mut skins: Query<(&OwnMaterial, &mut MeshMaterial3d<SkinMaterialAsset>)>,
) {
    for (character, view, heat) in &characters {
        let plain = view.weight_colors || heat.0.is_some();
        for part in &character.skins {
            if let Ok((own, mut drawn)) = skins.get_mut(part.entity) {
                let solid = if plain { &material.0 } else { &own.0 };
                let wanted = match view.opacity < 1.0 {
                    true => ghosts.of(solid, view.opacity, &mut materials),
                    false => solid.clone(),
                };
                if drawn.0 != wanted {
                    drawn.0 = wanted;
                }
            }
        }
    }
}

/// See-through copies of skin materials, by material and opacity (in hundredths).
#[derive(Resource, Default)]
pub struct GhostMaterials(std::collections::HashMap<(AssetId<SkinMaterialAsset>, u8), Handle<SkinMaterialAsset>>);

impl GhostMaterials {
    /// `solid` drawn at `opacity` (alpha blended, casting no shadow of its own).
    fn of(
        &mut self,
        solid: &Handle<SkinMaterialAsset>,
        opacity: f32,
        materials: &mut Assets<SkinMaterialAsset>,
    ) -> Handle<SkinMaterialAsset> {
        let key = (solid.id(), (opacity.clamp(0.0, 1.0) * 100.0).round() as u8);
        if let Some(ghost) = self.0.get(&key) {
            return ghost.clone();
        }
        let Some(mut ghost) = materials.get(solid).cloned() else { return solid.clone() };
        let alpha = ghost.base.base_color.alpha() * f32::from(key.1) / 100.0;
        ghost.base.base_color.set_alpha(alpha);
        ghost.base.alpha_mode = AlphaMode::Blend;
        let handle = materials.add(ghost);
        self.0.insert(key, handle.clone());
        handle
    }
}

/// A skin texture's pixels: a BMP file read now, or the image its character's file held.
fn picture_of(texture: &SkinTexture) -> Result<std::sync::Arc<crate::rig::Picture>, crate::formats::FormatError> {
    match texture {
        SkinTexture::File(path) => crate::formats::error::read_file(path)
            .and_then(|bytes| crate::formats::bmp::decode_bmp(&bytes, path))
            .map(std::sync::Arc::new),
        SkinTexture::Picture { picture, .. } => Ok(picture.clone()),
    }
}

/// Shows or hides skins by display mode (reads `CharacterView`; writes skin `Visibility`).
fn apply_display_mode(
    characters: Query<(&Character, &CharacterView), Changed<CharacterView>>,
    mut visibility: Query<&mut Visibility, With<SkinMesh>>,
) {
    for (character, view) in &characters {
        for part in &character.skins {
            if let Ok(mut v) = visibility.get_mut(part.entity) {
                v.set_if_neq(if view.display == DisplayDoc::Skeleton {
                    Visibility::Hidden
                } else {
                    Visibility::Inherited
                });
            }
        }
    }
}
