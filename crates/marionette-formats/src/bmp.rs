//! Uncompressed Windows bitmaps (`.bmp`, 24 or 32 bits per pixel), as CSE169's `head.bmp`
//! is: the texture a `.skin`'s `material` names.

use std::path::Path;

use super::error::FormatError;

/// An image as RGBA8 rows, top row first.
pub use marionette_rig::Picture as Rgba;

fn u16_at(b: &[u8], at: usize) -> Option<u16> {
    Some(u16::from_le_bytes(b.get(at..at + 2)?.try_into().ok()?))
}

fn u32_at(b: &[u8], at: usize) -> Option<u32> {
    Some(u32::from_le_bytes(b.get(at..at + 4)?.try_into().ok()?))
}

/// Decodes an uncompressed 24- or 32-bit BMP; anything else is an error that says what
/// the file is.
pub fn decode_bmp(bytes: &[u8], path: &Path) -> Result<Rgba, FormatError> {
    let bad = |what: String| FormatError::other(path, what);
    if bytes.get(0..2) != Some(b"BM") {
        return Err(bad("expected a BMP image (starting `BM`)".into()));
    }
    let header =
        |at| u32_at(bytes, at).ok_or_else(|| bad("expected a whole BMP header, found the end of the file".into()));
    let (data, width, raw_height) = (header(10)? as usize, header(18)? as i32, header(22)? as i32);
    let bits = u16_at(bytes, 28).unwrap_or(0);
    let compression = header(30)?;
    if compression != 0 || !(bits == 24 || bits == 32) {
        return Err(bad(format!(
            "expected an uncompressed 24- or 32-bit BMP, found {bits} bits per pixel, compression {compression}"
        )));
    }
    let (w, h) = (width.unsigned_abs(), raw_height.unsigned_abs());
    if width <= 0 || h == 0 || w > 16_384 || h > 16_384 {
        return Err(bad(format!("expected a size of 1 to 16384 pixels a side, found {width} x {raw_height}")));
    }
    let bytes_per_pixel = usize::from(bits / 8);
    let row = (w as usize * bytes_per_pixel).div_ceil(4) * 4;
    let needed = data + row * h as usize;
    if bytes.len() < needed {
        return Err(bad(format!("expected {needed} bytes of pixels and header, found {}", bytes.len())));
    }
    let mut pixels = Vec::with_capacity(w as usize * h as usize * 4);
    for y in 0..h as usize {
        // Rows are stored bottom-up unless the height is negative.
        let stored = if raw_height > 0 { h as usize - 1 - y } else { y };
        let start = data + stored * row;
        for x in 0..w as usize {
            let p = &bytes[start + x * bytes_per_pixel..start + (x + 1) * bytes_per_pixel];
            pixels.extend_from_slice(&[p[2], p[1], p[0], 255]);
        }
    }
    Ok(Rgba { width: w, height: h, pixels })
}
