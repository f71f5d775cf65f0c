//! The material every skin is drawn with: `StandardMaterial` (white, so vertex colours show
//! as they are) extended with a vertex shader that takes texture coordinates and colours
//! from one buffer every skin material reads (each skin's [`SkinAttributes`], written only
//! when they change; [`SkinAttributeStore`]) beside the positions of the mesh's vertex
//! buffer, and a fragment shader that lights each triangle with its own normal, from the
//! derivatives of the world position. The skinning system then hands the GPU only shared
//! vertex positions when a character moves: no unshared corners, no normals, no colours.
//! A normal-mapped skin's mesh has its skinned normals after each position: the shader
//! lights it with them (interpolated), bent by the map.

use bevy::asset::embedded_asset;
use bevy::mesh::MeshVertexBufferLayoutRef;
use bevy::pbr::{ExtendedMaterial, MaterialExtension, MaterialExtensionKey, MaterialExtensionPipeline, MaterialPlugin};
use bevy::prelude::*;
use bevy::render::render_asset::RenderAssets;
use bevy::render::render_resource::{AsBindGroup, RenderPipelineDescriptor, SpecializedMeshPipelineError};
use bevy::render::renderer::RenderQueue;
use bevy::render::storage::{GpuShaderBuffer, ShaderBuffer};
use bevy::render::{Extract, ExtractSchedule, RenderApp};
use bevy::shader::ShaderRef;

use crate::rig::material::Sampler;
use crate::scene::handoff::SkinAttributes;

/// The extension of `StandardMaterial` for skins: the vertex shader that reads the skin's
/// attributes beside its positions, the fragment shader (flat normals, or the skin's own)
/// and the normal map's scale.
#[derive(Asset, AsBindGroup, Reflect, Debug, Clone)]
pub struct SkinExtension {
    /// glTF's `normalTexture.scale` in x (the map's x and y are multiplied by it); y, z, w
    /// unused (a uniform of 16 bytes).
    #[uniform(100)]
    pub normal_scale: Vec4,
    /// Every skin surface's texture coordinates and colours, three words a vertex (see
    /// [`SkinAttributes`]), each surface from its mesh's `MeshTag` on
    /// ([`SkinAttributeStore`]).
    #[storage(101, read_only)]
    pub attributes: Handle<ShaderBuffer>,
}

impl MaterialExtension for SkinExtension {
    fn vertex_shader() -> ShaderRef {
        "embedded://marionette/editor/present/skin_vertex.wgsl".into()
    }

    fn prepass_vertex_shader() -> ShaderRef {
        "embedded://marionette/editor/present/skin_vertex.wgsl".into()
    }

    fn fragment_shader() -> ShaderRef {
        "embedded://marionette/editor/present/flat_normals.wgsl".into()
    }

    /// Every pass reads texture coordinates and colours (the prepasses too: a masked
    /// material's shadow is cut by its texture's alpha), which the mesh's layout (positions
    /// only) does not name: the vertex shader takes them from the attributes' buffer.
    fn specialize(
        _pipeline: &MaterialExtensionPipeline,
        descriptor: &mut RenderPipelineDescriptor,
        _layout: &MeshVertexBufferLayoutRef,
        _key: MaterialExtensionKey<Self>,
    ) -> Result<(), SpecializedMeshPipelineError> {
        let defs = ["VERTEX_UVS", "VERTEX_UVS_A", "VERTEX_COLORS"];
        descriptor.vertex.shader_defs.extend(defs.map(Into::into));
        if let Some(fragment) = descriptor.fragment.as_mut() {
            fragment.shader_defs.extend(defs.map(Into::into));
        }
        Ok(())
    }
}

/// The skin material type.
pub type SkinMaterialAsset = ExtendedMaterial<StandardMaterial, SkinExtension>;

/// One material for every skin without one of its own, and for any skin while it shows
/// weights or heat (only the vertex colours show).
#[derive(Resource)]
pub struct SkinMaterial(pub Handle<SkinMaterialAsset>);

/// Every skin surface's attributes in one buffer that all skin materials read, so that
/// skins of one material still share it (and are drawn together): each surface's first
/// vertex in the buffer is its mesh's `MeshTag`. The default has no room and no buffer
/// yet (see [`Self::empty_buffer`]).
#[derive(Resource, Default)]
pub struct SkinAttributeStore {
    pub buffer: Handle<ShaderBuffer>,
    /// Each skin entity's first vertex in the buffer.
    firsts: std::collections::HashMap<Entity, u32>,
    /// Vertices the buffer has room for.
    capacity: u32,
}

impl SkinAttributeStore {
    /// Bytes a vertex takes in the buffer.
    const VERTEX_BYTES: usize = std::mem::size_of::<[u32; 3]>();

    /// Lays the surfaces (each skin entity with its character's vertices) out one after
    /// another in the order given; true when they no longer fit the buffer, whose room is
    /// then grown (to spare, so that characters added later seldom grow it again): the
    /// caller makes it anew ([`Self::empty_buffer`]).
    pub fn lay_out(&mut self, surfaces: &[(Entity, u32)]) -> bool {
        self.firsts.clear();
        let mut next = 0u32;
        for &(entity, vertices) in surfaces {
            self.firsts.insert(entity, next);
            next += vertices;
        }
        let grown = next > self.capacity;
        if grown {
            self.capacity = next.next_power_of_two().max(4096);
        }
        grown
    }

    /// A buffer of the store's room (at least one vertex: a binding needs one element), zero.
    pub fn empty_buffer(&self) -> ShaderBuffer {
        let bytes = vec![0; self.capacity.max(1) as usize * Self::VERTEX_BYTES];
        ShaderBuffer::new(&bytes, bevy::asset::RenderAssetUsages::default())
    }

    /// The first vertex of a skin entity's surface in the buffer, once laid out.
    pub fn first(&self, skin: Entity) -> Option<u32> {
        self.firsts.get(&skin).copied()
    }

    /// Writes a surface's packed attributes (those of its character's `vertices`) at its
    /// place in the buffer; returns the place (bytes into the buffer) and the bytes written,
    /// none while they are not packed or it has no place.
    pub fn write<'a>(
        &self,
        buffer: &mut ShaderBuffer,
        skin: Entity,
        attributes: &'a SkinAttributes,
        vertices: &std::ops::Range<u32>,
    ) -> Option<(u64, &'a [u8])> {
        let words = attributes.0.get(vertices.start as usize..vertices.end as usize)?;
        let at = self.first(skin)? as usize * Self::VERTEX_BYTES;
        let packed: &[u8] = bytemuck::cast_slice(words);
        buffer.data.as_mut()?.get_mut(at..at + packed.len())?.copy_from_slice(packed);
        Some((at as u64, packed))
    }
}

/// The recoloured surfaces' attributes of this frame, for the render world to write into
/// the store's GPU buffer in place: a recolour changes the main world's copy without
/// telling the asset it changed, which would send the whole buffer again (every skin's
/// attributes, 6 MB for 64 SMPL bodies).
#[derive(Resource, Default)]
pub struct AttributeWrites {
    pub buffer: AssetId<ShaderBuffer>,
    /// Bytes into the buffer, and the bytes.
    pub writes: Vec<(u64, Vec<u8>)>,
}

/// Writes waiting in the render world for the store's buffer on the GPU: by buffer, the
/// place and bytes, and the frames waited.
#[derive(Resource, Default)]
struct PendingAttributeWrites(Vec<(AssetId<ShaderBuffer>, u64, Vec<u8>, u32)>);

/// Takes this frame's [`AttributeWrites`] and writes those waiting into their buffer once
/// it is on the GPU, at extraction: a system of its own in `Render`, even one that finds
/// nothing to write, lengthened the frame's mesh preparation by 0.1–0.15 ms (16 SMPL
/// bodies). Bevy's own write of a re-prepared buffer comes after it in the queue and holds
/// the same bytes (reads `AttributeWrites`, `RenderAssets<GpuShaderBuffer>`; writes
/// `PendingAttributeWrites`, GPU buffers).
fn write_attributes_in_place(
    main: Extract<Res<AttributeWrites>>,
    mut pending: ResMut<PendingAttributeWrites>,
    buffers: Res<RenderAssets<GpuShaderBuffer>>,
    queue: Res<RenderQueue>,
) {
    // The older writes first: a surface recoloured again overwrites its own bytes.
    pending.0.retain_mut(|(id, at, bytes, waited)| {
        if let Some(gpu) = buffers.get(*id) {
            queue.write_buffer(&gpu.buffer, *at, bytes);
            return false;
        }
        *waited += 1;
        *waited < crate::scene::handoff::MAX_WAIT_FRAMES
    });
    // This frame's writes straight from the main world's bytes; copied only to wait.
    for (at, bytes) in &main.writes {
        match buffers.get(main.buffer) {
            Some(gpu) => queue.write_buffer(&gpu.buffer, *at, bytes),
            None => pending.0.push((main.buffer, *at, bytes.clone(), 0)),
        }
    }
}

/// The store with a buffer of one vertex (laid out when the first skin comes), and the
/// shared plain material reading it.
fn setup_skin_material(
    mut commands: Commands,
    mut buffers: ResMut<Assets<ShaderBuffer>>,
    mut materials: ResMut<Assets<SkinMaterialAsset>>,
) {
    let mut store = SkinAttributeStore::default();
    store.buffer = buffers.add(store.empty_buffer());
    commands.insert_resource(SkinMaterial(materials.add(plain_skin_material(store.buffer.clone()))));
    commands.insert_resource(store);
}

/// The material of skins without one of their own, reading `attributes`.
fn plain_skin_material(attributes: Handle<ShaderBuffer>) -> SkinMaterialAsset {
    let base = StandardMaterial { base_color: Color::WHITE, perceptual_roughness: 0.75, ..default() };
    ExtendedMaterial { base, extension: SkinExtension { normal_scale: Vec4::new(1.0, 0.0, 0.0, 0.0), attributes } }
}

/// The skin textures on the GPU, by texture (a file's path, or the key of an image a
/// character's file holds), colour space and sampler: each uploaded once.
#[derive(Resource, Default)]
pub struct SkinTextures(std::collections::HashMap<(String, bool, Sampler), Handle<Image>>);

impl SkinTextures {
    /// The image of `texture` (whose pixels are `picture`), sRGB or linear, sampled by
    /// `sampler`.
    pub fn image(
        &mut self,
        texture: &crate::rig::SkinTexture,
        picture: &crate::rig::Picture,
        srgb: bool,
        sampler: Sampler,
        images: &mut Assets<Image>,
    ) -> Handle<Image> {
        let key = match texture {
            crate::rig::SkinTexture::File(path) => path.display().to_string(),
            crate::rig::SkinTexture::Picture { key, .. } => key.clone(),
        };
        self.0.entry((key, srgb, sampler)).or_insert_with(|| images.add(image_of(picture, srgb, sampler))).clone()
    }
}

/// A picture as an image the GPU samples (sRGB for colours, linear for data) as
/// `sampler` says.
fn image_of(picture: &crate::rig::Picture, srgb: bool, sampler: Sampler) -> Image {
    use crate::rig::material::Wrap;
    use bevy::image::{ImageAddressMode, ImageFilterMode, ImageSampler, ImageSamplerDescriptor};
    use bevy::render::render_resource::{Extent3d, TextureDimension, TextureFormat};
    let size = Extent3d { width: picture.width, height: picture.height, depth_or_array_layers: 1 };
    let format = if srgb { TextureFormat::Rgba8UnormSrgb } else { TextureFormat::Rgba8Unorm };
    let dimension = TextureDimension::D2;
    let mut image =
        Image::new(size, dimension, picture.pixels.clone(), format, bevy::asset::RenderAssetUsages::RENDER_WORLD);
    let wrap = |w| match w {
        Wrap::Repeat => ImageAddressMode::Repeat,
        Wrap::Mirror => ImageAddressMode::MirrorRepeat,
        Wrap::Clamp => ImageAddressMode::ClampToEdge,
    };
    let filter = |nearest| if nearest { ImageFilterMode::Nearest } else { ImageFilterMode::Linear };
    image.sampler = ImageSampler::Descriptor(ImageSamplerDescriptor {
        address_mode_u: wrap(sampler.wrap_u),
        address_mode_v: wrap(sampler.wrap_v),
        mag_filter: filter(sampler.nearest_mag),
        min_filter: filter(sampler.nearest_min),
        ..default()
    });
    image
}

/// The skin material of one of an asset's materials, reading `attributes`; `image` gives a
/// texture's image (sRGB or not), or none when it cannot be read. Skins have no tangents:
/// the shader bends their normals (skinned ones where the skin has them, else flat) by the
/// normal map (times its scale) in a frame from the derivatives.
pub fn skin_material_of(
    m: &crate::rig::material::Material,
    attributes: Handle<ShaderBuffer>,
    image: &mut impl FnMut(&crate::rig::SkinTexture, bool, Sampler) -> Option<Handle<Image>>,
) -> SkinMaterialAsset {
    use crate::rig::material::AlphaMode as Alpha;
    let mut texture = |t: &Option<crate::rig::material::TextureRef>, srgb: bool| {
        let t = t.as_ref()?;
        image(&t.image, srgb, t.sampler)
    };
    let base_color_texture = texture(&m.base_color_texture, true);
    let metallic_roughness = texture(&m.metallic_roughness_texture, false);
    let emissive = texture(&m.emissive_texture, true);
    let normal_map = texture(&m.normal_texture, false);
    let transform = m.base_color_texture.as_ref().map(|t| t.transform).unwrap_or_default();
    let [r, g, b, a] = m.base_color;
    let [er, eg, eb] = m.emissive;
    let base = StandardMaterial {
        base_color: Color::linear_rgba(r, g, b, a),
        base_color_texture,
        metallic: m.metallic,
        perceptual_roughness: m.roughness,
        metallic_roughness_texture: metallic_roughness,
        emissive: LinearRgba::rgb(er, eg, eb),
        emissive_texture: emissive,
        normal_map_texture: normal_map,
        alpha_mode: match m.alpha {
            Alpha::Opaque => AlphaMode::Opaque,
            Alpha::Mask(cutoff) => AlphaMode::Mask(cutoff),
            Alpha::Blend => AlphaMode::Blend,
        },
        double_sided: m.double_sided,
        unlit: m.unlit,
        cull_mode: if m.double_sided { None } else { Some(bevy::render::render_resource::Face::Back) },
        uv_transform: bevy::math::Affine2::from_scale_angle_translation(
            transform.scale,
            transform.rotation,
            transform.offset,
        ),
        ..default()
    };
    let normal_scale = Vec4::new(m.normal_scale, 0.0, 0.0, 0.0);
    ExtendedMaterial { base, extension: SkinExtension { normal_scale, attributes } }
}

pub struct SkinMaterialPlugin;

impl Plugin for SkinMaterialPlugin {
    fn build(&self, app: &mut App) {
        embedded_asset!(app, "flat_normals.wgsl");
        embedded_asset!(app, "skin_vertex.wgsl");
        app.init_resource::<SkinTextures>()
            .init_resource::<AttributeWrites>()
            .add_plugins(MaterialPlugin::<SkinMaterialAsset>::default())
            .add_systems(Startup, setup_skin_material);
        let Some(render_app) = app.get_sub_app_mut(RenderApp) else { return };
        render_app.init_resource::<PendingAttributeWrites>().add_systems(ExtractSchedule, write_attributes_in_place);
    }
}
