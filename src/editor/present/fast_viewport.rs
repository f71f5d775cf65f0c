//! The fast viewport, for machines that draw on the CPU (Mesa's llvmpipe): while the user
//! works the view (a button held in it, the wheel turned, a clip playing) it is drawn at a
//! fraction of its pixels, without multisampling and with a small shadow map, into an image
//! the panels stretch over the viewport; once the view has been still for a moment the
//! window's camera draws it at full quality again. On by default where the renderer runs on
//! the CPU; the View panel switches it.

use std::time::{Duration, Instant};

use bevy::camera::RenderTarget;
use bevy::input::mouse::MouseWheel;
use bevy::light::DirectionalLightShadowMap;
use bevy::prelude::*;
use bevy::render::render_resource::{Extent3d, TextureFormat};

use crate::editor::present::redraw::{DrawMode, WakeWithin};
use crate::editor::state::ViewportHasPointer;
use crate::editor::state::camera::OrbitCamera;

/// The setting: whether the view is drawn fast while it moves, and at what share of its
/// pixels along each side.
#[derive(Resource, Debug, Clone, Copy, PartialEq)]
pub struct FastViewport {
    pub enabled: bool,
    pub scale: f32,
}

impl Default for FastViewport {
    fn default() -> Self {
        Self { enabled: false, scale: DEFAULT_SCALE }
    }
}

/// The share of the viewport's pixels along each side drawn while it moves.
pub const DEFAULT_SCALE: f32 = 0.25;

/// How long the view stays fast after the last interaction.
pub const SETTLE: Duration = Duration::from_millis(250);

/// The shadow map's side while the view moves.
const FAST_SHADOW_MAP: usize = 512;

/// The fast view as it is now: its image (and egui's name for it) while it is shown.
#[derive(Resource, Default)]
pub struct FastView {
    image: Handle<Image>,
    /// egui's texture of the image, while the fast view is shown.
    pub shown: Option<bevy_egui::egui::TextureId>,
    last_interaction: Option<Instant>,
    /// The shadow map's side at full quality.
    full_shadow_map: Option<usize>,
}

/// The camera that draws the fast view (a child of the window's camera: it sees what it sees).
#[derive(Component)]
struct FastCamera;

pub struct FastViewportPlugin;

impl Plugin for FastViewportPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<FastViewport>()
            .init_resource::<FastView>()
            .add_systems(Startup, enable_on_cpu_renderers)
            .add_systems(PostStartup, spawn_fast_camera)
            .add_systems(
                PostUpdate,
                switch_fast_view
                    .in_set(crate::editor::order::EditorSystems::Present)
                    .before(bevy::transform::TransformSystems::Propagate),
            );
    }
}

/// Whether the view is drawn fast: enabled, and an interaction within [`SETTLE`].
pub fn fast_wanted(enabled: bool, since_interaction: Option<Duration>) -> bool {
    enabled && since_interaction.is_some_and(|d| d < SETTLE)
}

/// The fast image's size for a viewport of `size` physical pixels: `scale` of each side,
/// at least a pixel.
pub fn fast_size(size: UVec2, scale: f32) -> UVec2 {
    (size.as_vec2() * scale.clamp(0.05, 1.0)).round().as_uvec2().max(UVec2::ONE)
}

/// Turns the fast viewport on where the renderer draws on the CPU, unless
/// `MARIONETTE_FAST_VIEWPORT` says `0` (off), `1` (on everywhere) or a scale below 1 (on,
/// at that scale) (reads the adapter).
fn enable_on_cpu_renderers(
    adapter: Option<Res<bevy::render::renderer::RenderAdapterInfo>>,
    mut fast: ResMut<FastViewport>,
) {
    let asked = std::env::var("MARIONETTE_FAST_VIEWPORT").ok().and_then(|v| v.parse::<f32>().ok());
    fast.enabled = match asked {
        Some(v) => v > 0.0,
        None => adapter.is_some_and(|a| a.device_type == wgpu_types::DeviceType::Cpu),
    };
    if let Some(scale) = asked.filter(|v| *v > 0.0 && *v < 1.0) {
        fast.scale = scale;
    }
}

/// Spawns the fast camera, off, under the window's camera (writes entities, `FastView`).
fn spawn_fast_camera(
    mut commands: Commands,
    mut images: ResMut<Assets<Image>>,
    mut view: ResMut<FastView>,
    cameras: Query<Entity, With<OrbitCamera>>,
) {
    let Some(parent) = cameras.iter().next() else { return };
    let image = Image::new_target_texture(16, 16, TextureFormat::Rgba8UnormSrgb, None);
    view.image = images.add(image);
    let camera = Camera { is_active: false, order: -1, ..default() };
    let target = RenderTarget::Image(view.image.clone().into());
    let slot = crate::scene::Slot(0).marks();
    commands.entity(parent).with_child((FastCamera, Camera3d::default(), camera, target, Msaa::Off, slot));
}

/// Shows the fast view while the user works the view and the full one once it is still:
/// the cameras switched, the fast image sized to the viewport, the shadow map made small,
/// and a frame asked for when the view settles (reads input, `DrawMode`; writes the
/// cameras, the image, `DirectionalLightShadowMap`, `FastView`, `WakeWithin`).
#[allow(clippy::too_many_arguments)]
fn switch_fast_view(
    settings: Res<FastViewport>,
    buttons: Res<ButtonInput<MouseButton>>,
    mut wheel: MessageReader<MouseWheel>,
    pointer: Res<ViewportHasPointer>,
    mode: Res<DrawMode>,
    mut view: ResMut<FastView>,
    mut main: Query<(&mut Camera, Ref<Projection>), (With<OrbitCamera>, Without<FastCamera>)>,
    mut fast: Query<(&mut Camera, &mut Projection), With<FastCamera>>,
    mut images: ResMut<Assets<Image>>,
    mut shadow_map: ResMut<DirectionalLightShadowMap>,
    mut textures: ResMut<bevy_egui::EguiUserTextures>,
    mut wake: ResMut<WakeWithin>,
) {
    let now = Instant::now();
    let wheeled = wheel.read().count() > 0;
    let held = pointer.0 && buttons.get_pressed().next().is_some();
    if settings.enabled && (wheeled || held || mode.0 == Some("playing")) {
        view.last_interaction = Some(now);
    }
    let wanted = fast_wanted(settings.enabled, view.last_interaction.map(|t| now - t));
    let (Ok((mut main_camera, projection)), Ok((mut fast_camera, mut fast_projection))) =
        (main.single_mut(), fast.single_mut())
    else {
        return;
    };
    if wanted {
        let viewport = main_camera.viewport.as_ref().map(|v| v.physical_size).or(main_camera.physical_target_size());
        let size = fast_size(viewport.unwrap_or(UVec2::ONE), settings.scale);
        if let Some(image) = images.get(&view.image)
            && image.size() != size
            && let Some(mut image) = images.get_mut(&view.image)
        {
            image.resize(Extent3d { width: size.x, height: size.y, depth_or_array_layers: 1 });
        }
        if projection.is_changed() || !fast_camera.is_active {
            *fast_projection = (*projection).clone();
        }
        let full = *view.full_shadow_map.get_or_insert(shadow_map.size);
        if shadow_map.size != FAST_SHADOW_MAP.min(full) {
            shadow_map.size = FAST_SHADOW_MAP.min(full);
        }
        view.shown = Some(textures.add_image(bevy_egui::EguiTextureHandle::Weak(view.image.id())));
        // Wake to draw the full view once the view has settled.
        if let Some(t) = view.last_interaction {
            wake.ask((t + SETTLE).saturating_duration_since(now) + Duration::from_millis(5));
        }
    } else {
        view.shown = None;
        if let Some(full) = view.full_shadow_map.take()
            && shadow_map.size != full
        {
            shadow_map.size = full;
        }
    }
    if main_camera.is_active == wanted {
        main_camera.is_active = !wanted;
    }
    if fast_camera.is_active != wanted {
        fast_camera.is_active = wanted;
    }
}
