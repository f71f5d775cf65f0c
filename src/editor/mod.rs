//! The windowed app: stage, orbit camera, characters, skeleton overlay.

pub mod camera;
pub mod default_scene;
pub mod stage;

use std::path::PathBuf;
use std::sync::Arc;

use bevy::prelude::*;
use bevy::window::WindowResolution;

use crate::formats::load_character;
use crate::rig::CharacterAsset;
use crate::rig::JointRotation;
use crate::scene::{Character, CurrentJointToWorld, DisplayMode, Joint, MarionetteSystems, Placement, RigCorePlugin, SkinMesh, SkinningPlugin, spawn_character_posed};
use camera::{OrbitCamera, apply_orbit_camera, orbit_camera_input};
use stage::{StageSettings, apply_stage_settings, draw_grid_and_axes, spawn_stage};

/// What the editor opens with: character files, or the default scene when empty.
#[derive(Resource, Clone, Debug, Default)]
pub struct StartupPaths(pub Vec<PathBuf>);

/// Messages for the user (load errors and warnings), newest last.
#[derive(Resource, Clone, Debug, Default)]
pub struct Messages(pub Vec<String>);

/// One material for every skin: white, so vertex colours (tint or weights) show as they are.
#[derive(Resource)]
pub struct SkinMaterial(pub Handle<StandardMaterial>);

/// Everything the windowed editor adds to the core plugins.
pub struct EditorPlugin;

impl Plugin for EditorPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<StageSettings>()
            .init_resource::<Messages>()
            .init_resource::<StartupPaths>()
            .add_systems(Startup, (setup_skin_material, spawn_stage, spawn_camera, open_startup_paths).chain())
            .add_systems(Update, (orbit_camera_input, apply_orbit_camera).chain())
            .add_systems(
                PostUpdate,
                (attach_skin_material, apply_display_mode, apply_stage_settings, draw_skeletons, draw_grid_and_axes).in_set(MarionetteSystems::Draw),
            );
    }
}

/// Opens the editor window on `paths` (or on the default scene) and runs until closed.
pub fn run(paths: Vec<PathBuf>) {
    App::new()
        .add_plugins(DefaultPlugins.set(WindowPlugin {
            primary_window: Some(Window { title: "Marionette".into(), resolution: WindowResolution::new(1280, 800), ..default() }),
            ..default()
        }))
        .insert_resource(ClearColor(Color::srgb(0.62, 0.7, 0.78)))
        .insert_resource(StartupPaths(paths))
        .add_plugins((RigCorePlugin, SkinningPlugin, EditorPlugin))
        .run();
}

fn setup_skin_material(mut commands: Commands, mut materials: ResMut<Assets<StandardMaterial>>) {
    let material = materials.add(StandardMaterial { base_color: Color::WHITE, perceptual_roughness: 0.75, ..default() });
    commands.insert_resource(SkinMaterial(material));
}

fn spawn_camera(mut commands: Commands) {
    let orbit = OrbitCamera::default();
    commands.spawn((Camera3d::default(), orbit, orbit.transform()));
}

/// Loads the startup paths (or the default scene), spawns the characters side by side
/// and frames them (writes entities, `Messages`, `OrbitCamera`).
fn open_startup_paths(
    mut commands: Commands,
    mut meshes: ResMut<Assets<Mesh>>,
    paths: Res<StartupPaths>,
    mut messages: ResMut<Messages>,
    mut cameras: Query<&mut OrbitCamera>,
) {
    let placed: Vec<Placed> = if paths.0.is_empty() {
        default_scene::characters()
    } else {
        let mut loaded = Vec::new();
        for path in &paths.0 {
            match load_character(path) {
                Ok(asset) => {
                    messages.0.extend(asset.warnings.iter().cloned());
                    loaded.push(Arc::new(asset));
                }
                Err(e) => {
                    error!("{e}");
                    messages.0.push(e.to_string());
                }
            }
        }
        side_by_side(loaded)
    };
    let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
    for (asset, placement, pose) in placed {
        let (a, b) = asset.bounds();
        let m = placement.to_mat4();
        lo = lo.min(m.transform_point3(a)).min(m.transform_point3(b));
        hi = hi.max(m.transform_point3(a)).max(m.transform_point3(b));
        spawn_character_posed(&mut commands, &mut meshes, asset, placement, &pose);
    }
    if lo.x <= hi.x {
        for mut orbit in &mut cameras {
            *orbit = OrbitCamera::framing(lo, hi);
        }
    }
}

/// A character to spawn: its asset, where it stands, its pose.
pub type Placed = (Arc<CharacterAsset>, Placement, Vec<JointRotation>);

/// Places characters in a row along x, each standing on the floor (y = 0).
pub fn side_by_side(assets: Vec<Arc<CharacterAsset>>) -> Vec<Placed> {
    let gap = 0.15;
    let widths: Vec<f32> = assets.iter().map(|a| { let (lo, hi) = a.bounds(); (hi.x - lo.x).max(0.1) }).collect();
    let total: f32 = widths.iter().sum::<f32>() + gap * (assets.len().saturating_sub(1)) as f32;
    let mut x = -total / 2.0;
    assets
        .into_iter()
        .zip(widths)
        .map(|(asset, w)| {
            let (lo, hi) = asset.bounds();
            let center = (lo + hi) / 2.0;
            let placement = Placement::at(Vec3::new(x + w / 2.0 - center.x, -lo.y, -center.z));
            x += w + gap;
            let pose = asset.skeleton.initial_pose();
            (asset, placement, pose)
        })
        .collect()
}

/// Gives new skin meshes the shared material (writes `MeshMaterial3d`).
fn attach_skin_material(mut commands: Commands, material: Res<SkinMaterial>, new_skins: Query<Entity, Added<SkinMesh>>) {
    for entity in &new_skins {
        commands.entity(entity).insert(MeshMaterial3d(material.0.clone()));
    }
}

/// Shows or hides skins by display mode (reads `DisplayMode`; writes `Visibility`).
fn apply_display_mode(characters: Query<(&Character, Option<&DisplayMode>), Changed<DisplayMode>>, mut visibility: Query<&mut Visibility, With<SkinMesh>>) {
    for (character, mode) in &characters {
        if let Ok(mut v) = visibility.get_mut(character.skin_entity) {
            *v = if mode == Some(&DisplayMode::Skeleton) { Visibility::Hidden } else { Visibility::Inherited };
        }
    }
}

/// Draws joints and bones of characters in skeleton view (reads joint matrices; gizmos).
fn draw_skeletons(characters: Query<(&Character, &DisplayMode)>, joints: Query<(&Joint, &CurrentJointToWorld)>, mut gizmos: Gizmos) {
    for (character, mode) in &characters {
        if *mode == DisplayMode::Mesh {
            continue;
        }
        let (lo, hi) = character.asset.bounds();
        let radius = ((hi - lo).length() * 0.008).max(0.004);
        for (j, &entity) in character.joints.iter().enumerate() {
            let Ok((_, current)) = joints.get(entity) else { continue };
            let p = current.position();
            gizmos.sphere(Isometry3d::from_translation(p), radius, Color::srgb(1.0, 0.85, 0.2));
            if let Some(parent) = character.asset.skeleton.parent(j)
                && let Ok((_, pc)) = joints.get(character.joints[parent])
            {
                gizmos.line(pc.position(), p, Color::srgb(0.95, 0.95, 1.0));
            }
        }
    }
}
