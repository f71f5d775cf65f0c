//! The data pictures on disk, beside the picture `shot.png`: `shot.depth.exr` (32-bit float
//! metres along the view axis, channel `Z`, infinity where nothing was hit),
//! `shot.depth.png` (16-bit millimetres, 0 where nothing was hit), `shot.normal.png`
//! (camera-frame normals, x right, y up, z towards the camera, as n · 0.5 + 0.5; black
//! where nothing was hit), `shot.mask.png` (16-bit instance ids), `shot.parts.png` (8-bit
//! body-part ids), `shot.openpose.png` and `shot.openpose.json`; the COCO file is the
//! caller's (one a picture, or one a sequence).

use std::path::{Path, PathBuf};

use image::{ImageBuffer, Luma, Rgb, RgbImage};

use super::controlnet::ControlNet;
use super::raster::FLOOR;
use super::{Figure, Passes, Pinhole, openpose};

/// A data picture or JSON file that could not be written.
#[derive(Debug, thiserror::Error)]
pub enum WriteError {
    #[error("{}: {source}", path.display())]
    Image { path: PathBuf, source: image::ImageError },
    #[error("{}: {source}", path.display())]
    Exr { path: PathBuf, source: exr::error::Error },
    #[error("{}: {source}", path.display())]
    Io { path: PathBuf, source: std::io::Error },
    #[error("{0}")]
    Json(#[from] serde_json::Error),
}

/// The file beside `picture` with `suffix` in place of its extension (`shot.png`,
/// `depth.exr` → `shot.depth.exr`).
pub fn beside(picture: &Path, suffix: &str) -> PathBuf {
    let stem = picture.file_stem().map_or_else(|| "shot".into(), |s| s.to_string_lossy().into_owned());
    picture.with_file_name(format!("{stem}.{suffix}"))
}

/// Writes every pass and OpenPose's files beside `picture`.
pub fn passes(picture: &Path, camera: &Pinhole, passes: &Passes, figures: &[Figure]) -> Result<(), WriteError> {
    depth_exr(&beside(picture, "depth.exr"), passes)?;
    let (w, h) = (passes.width, passes.height);
    let millimetres = ImageBuffer::<Luma<u16>, _>::from_fn(w, h, |x, y| {
        let d = passes.depth[passes.at(x, y)];
        Luma([if d.is_finite() { (d * 1000.0).round().clamp(1.0, 65535.0) as u16 } else { 0 }])
    });
    save(&millimetres, &beside(picture, "depth.png"))?;
    let normals = RgbImage::from_fn(w, h, |x, y| {
        let n = passes.normal[passes.at(x, y)];
        if n == glam::Vec3::ZERO {
            return Rgb([0, 0, 0]);
        }
        Rgb(normal_of_map(n).to_array().map(|c| ((c * 0.5 + 0.5) * 255.0).round() as u8))
    });
    save(&normals, &beside(picture, "normal.png"))?;
    let mask = ImageBuffer::<Luma<u16>, _>::from_fn(w, h, |x, y| Luma([mask_id(passes.instance[passes.at(x, y)])]));
    save(&mask, &beside(picture, "mask.png"))?;
    let parts = ImageBuffer::<Luma<u8>, _>::from_fn(w, h, |x, y| Luma([passes.part[passes.at(x, y)]]));
    save(&parts, &beside(picture, "parts.png"))?;
    save(&openpose::drawing(camera, passes, figures), &beside(picture, "openpose.png"))?;
    json(&beside(picture, "openpose.json"), &openpose::json(camera, passes, figures))
}

/// A normal of the passes (OpenCV's camera frame) in the normal map's: x right, y up, z
/// towards the camera.
pub fn normal_of_map(n: glam::Vec3) -> glam::Vec3 {
    glam::Vec3::new(n.x, -n.y, -n.z)
}

/// An instance of the passes as the mask holds it: the floor is nothing (0).
pub fn mask_id(instance: u16) -> u16 {
    if instance == FLOOR { 0 } else { instance }
}

/// Writes the maps ControlNet reads beside `picture` ([`super::controlnet`]):
/// `shot.cn-openpose.png` and `.json`, `shot.cn-depth.png`, `shot.cn-normal.png`, and with
/// `maps.canny` the edges of the picture written at `picture`, `shot.cn-canny.png` ([`super::canny`]).
pub fn controlnet(
    picture: &Path,
    camera: &Pinhole,
    passes: &Passes,
    figures: &[Figure],
    maps: ControlNet,
) -> Result<(), WriteError> {
    let shown = match maps.canny {
        Some(_) => {
            image::open(picture).map_err(|source| WriteError::Image { path: picture.to_owned(), source })?.to_rgb8()
        }
        None => RgbImage::new(0, 0),
    };
    let maps = super::controlnet::maps(camera, passes, figures, maps, &shown);
    save(&maps.openpose, &beside(picture, "cn-openpose.png"))?;
    json(&beside(picture, "cn-openpose.json"), &maps.openpose_json)?;
    save(&maps.depth, &beside(picture, "cn-depth.png"))?;
    save(&maps.normal, &beside(picture, "cn-normal.png"))?;
    maps.canny.map_or(Ok(()), |edges| save(&edges, &beside(picture, "cn-canny.png")))
}

/// Writes `value` as JSON.
pub fn json(path: &Path, value: &serde_json::Value) -> Result<(), WriteError> {
    let text = serde_json::to_string(value)?;
    std::fs::write(path, text).map_err(|source| WriteError::Io { path: path.to_owned(), source })
}

fn save<P, C>(image: &ImageBuffer<P, C>, path: &Path) -> Result<(), WriteError>
where
    P: image::Pixel + image::PixelWithColorType,
    [P::Subpixel]: image::EncodableLayout,
    C: std::ops::Deref<Target = [P::Subpixel]>,
{
    image
        .save_with_format(path, image::ImageFormat::Png)
        .map_err(|source| WriteError::Image { path: path.to_owned(), source })
}

/// The depth pass as a one-channel (`Z`) 32-bit float OpenEXR file.
fn depth_exr(path: &Path, passes: &Passes) -> Result<(), WriteError> {
    use exr::prelude::*;
    let width = passes.width as usize;
    let channels = SpecificChannels::build()
        .with_channel("Z")
        .with_pixel_fn(|at: Vec2<usize>| (passes.depth[at.y() * width + at.x()],));
    let image = Image::from_channels((width, passes.height as usize), channels);
    image.write().to_file(path).map_err(|source| WriteError::Exr { path: path.to_owned(), source })
}
