//! A rendered picture finished for saving: supersampled pixels averaged down, and the
//! background put behind what was drawn (a gradient, or nothing: alpha kept).

use image::{DynamicImage, Rgba, RgbaImage};

use marionette_formats::scene::BackgroundDoc;

/// sRGB (0..=1) to linear light.
fn to_linear(c: f32) -> f32 {
    if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }
}

/// Linear light to sRGB (0..=1).
fn to_srgb(c: f32) -> f32 {
    if c <= 0.0031308 { c * 12.92 } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 }
}

fn byte(c: f32) -> u8 {
    (c.clamp(0.0, 1.0) * 255.0).round() as u8
}

/// Each `samples`×`samples` block of `rendered` averaged into one pixel: colours in linear
/// light, weighted by their alpha (a pixel half covered by a character and half by nothing
/// keeps the character's colour at half alpha).
pub fn downsampled(rendered: &RgbaImage, samples: u32) -> RgbaImage {
    if samples <= 1 {
        return rendered.clone();
    }
    let (w, h) = (rendered.width() / samples, rendered.height() / samples);
    let n = (samples * samples) as f32;
    RgbaImage::from_fn(w, h, |x, y| {
        let mut sum = [0.0f32; 4];
        for dy in 0..samples {
            for dx in 0..samples {
                let p = rendered.get_pixel(x * samples + dx, y * samples + dy).0;
                let alpha = p[3] as f32 / 255.0;
                for k in 0..3 {
                    sum[k] += to_linear(p[k] as f32 / 255.0) * alpha;
                }
                sum[3] += alpha;
            }
        }
        let alpha = sum[3] / n;
        let color = |k: usize| if sum[3] > 0.0 { byte(to_srgb(sum[k] / sum[3])) } else { 0 };
        Rgba([color(0), color(1), color(2), byte(alpha)])
    })
}

/// `drawn` over the background: a gradient fills behind it (composited in linear light);
/// a transparent background keeps the alpha (an RGBA picture); any other is already in
/// the picture (an RGB one).
/// `drawn` (RGBA, sRGB) over the colour (sRGB) `behind` gives each pixel, blended in linear
/// light; opaque.
fn composite(drawn: RgbaImage, behind: impl Fn(u32, u32) -> [f32; 3]) -> DynamicImage {
    let mut out = drawn;
    for (x, y, p) in out.enumerate_pixels_mut() {
        let alpha = p.0[3] as f32 / 255.0;
        for (c, back) in p.0.iter_mut().zip(behind(x, y)) {
            let front = to_linear(*c as f32 / 255.0);
            *c = byte(to_srgb(front * alpha + to_linear(back) * (1.0 - alpha)));
        }
        p.0[3] = 255;
    }
    DynamicImage::ImageRgb8(DynamicImage::ImageRgba8(out).to_rgb8())
}

/// `drawn` over the picture `behind`, scaled to fill the frame (its middle kept where the
/// shapes differ); opaque. A picture already opaque is returned as it is.
pub fn over_picture(drawn: DynamicImage, behind: &DynamicImage) -> DynamicImage {
    let filled = reference_picture(behind, true, drawn.width(), drawn.height());
    composite(drawn.to_rgba8(), |x, y| filled.get_pixel(x, y).0.map(|c| c as f32 / 255.0))
}

/// `picture` at `w`×`h`: scaled to cover it (`fill`, its middle kept), else to fit inside it,
/// centred on the sky's colour.
pub fn reference_picture(picture: &DynamicImage, fill: bool, w: u32, h: u32) -> image::RgbImage {
    use image::imageops::FilterType::Triangle;
    if fill {
        return picture.resize_to_fill(w, h, Triangle).to_rgb8();
    }
    let fitted = picture.resize(w, h, Triangle).to_rgb8();
    let sky = marionette_formats::stage::SKY.map(|c| (c * 255.0).round() as u8);
    let mut out = image::RgbImage::from_pixel(w, h, image::Rgb(sky));
    let (x, y) = ((w - fitted.width()) / 2, (h - fitted.height()) / 2);
    image::imageops::replace(&mut out, &fitted, i64::from(x), i64::from(y));
    out
}

/// The reference picture behind a scene could not be read.
#[derive(Debug, thiserror::Error)]
#[error("{}: {source}", path.display())]
pub struct BackgroundError {
    pub path: std::path::PathBuf,
    pub source: image::ImageError,
}

pub fn over_background(drawn: RgbaImage, background: &BackgroundDoc) -> Result<DynamicImage, BackgroundError> {
    Ok(match background {
        BackgroundDoc::Image { path, fill } => {
            let behind = image::open(path).map_err(|source| BackgroundError { path: path.clone(), source })?;
            let behind = reference_picture(&behind, *fill, drawn.width(), drawn.height());
            composite(drawn, |x, y| behind.get_pixel(x, y).0.map(|c| c as f32 / 255.0))
        }
        BackgroundDoc::Transparent => DynamicImage::ImageRgba8(drawn),
        BackgroundDoc::Gradient { .. } => {
            let height = drawn.height().max(2) - 1;
            composite(drawn, |_, y| background.at(y as f32 / height as f32).0)
        }
        BackgroundDoc::Sky | BackgroundDoc::Color(_) => {
            DynamicImage::ImageRgb8(DynamicImage::ImageRgba8(drawn).to_rgb8())
        }
    })
}
