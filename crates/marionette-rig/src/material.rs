//! How a character's surfaces look: materials (glTF's metallic-roughness model) and the
//! ranges of the mesh each one covers. Plain data; the editor turns them into its own.

use std::ops::Range;

use glam::Vec2;

/// A material: glTF 2.0's `pbrMetallicRoughness` with its normal map, emission, alpha
/// and sidedness. Factors multiply their textures (and the vertex colours).
#[derive(Debug, Clone, PartialEq)]
pub struct Material {
    pub name: String,
    /// Linear RGBA.
    pub base_color: [f32; 4],
    pub base_color_texture: Option<TextureRef>,
    pub metallic: f32,
    pub roughness: f32,
    /// Roughness in G, metalness in B.
    pub metallic_roughness_texture: Option<TextureRef>,
    pub normal_texture: Option<TextureRef>,
    pub normal_scale: f32,
    /// Linear RGB.
    pub emissive: [f32; 3],
    pub emissive_texture: Option<TextureRef>,
    pub alpha: AlphaMode,
    pub double_sided: bool,
    /// Shown in its own colour, unlit (glTF's `KHR_materials_unlit`; a VRM avatar's unlit
    /// MToon fallback).
    pub unlit: bool,
}

impl Default for Material {
    /// glTF's default material: white, fully metallic and rough, opaque, one-sided.
    fn default() -> Self {
        Self {
            name: String::new(),
            base_color: [1.0; 4],
            base_color_texture: None,
            metallic: 1.0,
            roughness: 1.0,
            metallic_roughness_texture: None,
            normal_texture: None,
            normal_scale: 1.0,
            emissive: [0.0; 3],
            emissive_texture: None,
            alpha: AlphaMode::Opaque,
            double_sided: false,
            unlit: false,
        }
    }
}

impl Material {
    /// A dielectric material showing `image` (a course format's texture).
    pub fn textured(name: impl Into<String>, image: SkinTexture) -> Self {
        Self {
            name: name.into(),
            base_color_texture: Some(TextureRef::plain(image)),
            metallic: 0.0,
            roughness: 0.75,
            ..Self::default()
        }
    }

    /// Its textures, each with what it is for.
    pub fn textures(&self) -> impl Iterator<Item = (&'static str, &TextureRef)> {
        [
            ("base colour", &self.base_color_texture),
            ("metallic-roughness", &self.metallic_roughness_texture),
            ("normal", &self.normal_texture),
            ("emissive", &self.emissive_texture),
        ]
        .into_iter()
        .filter_map(|(what, t)| Some((what, t.as_ref()?)))
    }
}

/// How a material's alpha is used.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum AlphaMode {
    Opaque,
    /// Drawn where alpha is at least the cutoff, not drawn elsewhere.
    Mask(f32),
    Blend,
}

/// A texture as a material uses it: its image, sampler and texture-coordinate transform.
#[derive(Debug, Clone, PartialEq)]
pub struct TextureRef {
    pub image: SkinTexture,
    pub sampler: Sampler,
    pub transform: TextureTransform,
}

impl TextureRef {
    /// `image` repeated, filtered linearly, untransformed.
    pub fn plain(image: SkinTexture) -> Self {
        Self { image, sampler: Sampler::default(), transform: TextureTransform::default() }
    }
}

/// How a texture is sampled (glTF's sampler).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Sampler {
    pub wrap_u: Wrap,
    pub wrap_v: Wrap,
    /// Nearest-texel magnification (else linear).
    pub nearest_mag: bool,
    /// Nearest-texel minification (else linear).
    pub nearest_min: bool,
}

impl Default for Sampler {
    fn default() -> Self {
        Self { wrap_u: Wrap::Repeat, wrap_v: Wrap::Repeat, nearest_mag: false, nearest_min: false }
    }
}

/// What texture coordinates outside 0..1 read.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Wrap {
    Repeat,
    Mirror,
    Clamp,
}

/// `KHR_texture_transform`: `uv' = T(offset) · R(rotation) · S(scale) · uv` (see
/// [`TextureTransform::apply`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TextureTransform {
    pub offset: Vec2,
    /// Radians, counter-clockwise in texture space.
    pub rotation: f32,
    pub scale: Vec2,
}

impl Default for TextureTransform {
    fn default() -> Self {
        Self { offset: Vec2::ZERO, rotation: 0.0, scale: Vec2::ONE }
    }
}

impl TextureTransform {
    /// The transformed coordinates of `uv`. The rotation turns the image counter-clockwise
    /// as it is seen (v runs down), as the extension's example has it: offset (0, 1),
    /// rotation π/2 and scale ½ show the lower left quadrant turned a quarter clockwise
    /// (three.js reads it so).
    pub fn apply(&self, uv: Vec2) -> Vec2 {
        let (s, c) = self.rotation.sin_cos();
        let scaled = uv * self.scale;
        Vec2::new(c * scaled.x + s * scaled.y, -s * scaled.x + c * scaled.y) + self.offset
    }
}

/// Appends `surface`, merged into the last one when it goes on from it in the same
/// material.
pub fn push_surface(surfaces: &mut Vec<Surface>, surface: Surface) {
    match surfaces.last_mut() {
        Some(last)
            if last.material == surface.material
                && last.vertices.end == surface.vertices.start
                && last.triangles.end == surface.triangles.start =>
        {
            last.vertices.end = surface.vertices.end;
            last.triangles.end = surface.triangles.end;
        }
        _ => surfaces.push(surface),
    }
}

/// A run of the mesh drawn with one material: its vertices and triangles (indices into
/// the skin's), and the material (none: the character's own tint).
#[derive(Debug, Clone, PartialEq)]
pub struct Surface {
    pub vertices: Range<u32>,
    pub triangles: Range<u32>,
    pub material: Option<usize>,
}

/// A skin's base colour image.
#[derive(Debug, Clone, PartialEq)]
pub enum SkinTexture {
    /// A file beside the character's (read when it is shown).
    File(std::path::PathBuf),
    /// An image the character's file holds, decoded; `key` names it (file and image index).
    Picture { key: String, picture: std::sync::Arc<Picture> },
}

/// An image as RGBA8 (sRGB) rows, top row first.
#[derive(Debug, Clone, PartialEq)]
pub struct Picture {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<u8>,
}
