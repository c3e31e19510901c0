//! 8-bit RGB images as PNG bytes: the payload of Foxglove's `CompressedImage` messages in datasets and the terrain
//! maps' pictures. Decoding checks the size against what the caller declares before allocating, so a forged header
//! cannot ask for gigabytes.

use crate::error::{Error, Result};

pub fn encode_rgb(width: u32, height: u32, rgb: &[u8]) -> Result<Vec<u8>> {
    if rgb.len() != (width as usize) * (height as usize) * 3 {
        return Err(Error::data(format!("frame of {} bytes is not {width} × {height} RGB", rgb.len())));
    }
    let mut out = Vec::new();
    let mut encoder = png::Encoder::new(&mut out, width, height);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    let fail = |e: png::EncodingError| Error::data(format!("PNG encoding failed: {e}"));
    let mut writer = encoder.write_header().map_err(fail)?;
    writer.write_image_data(rgb).map_err(fail)?;
    writer.finish().map_err(fail)?;
    Ok(out)
}

/// The RGB pixels of a PNG that must be exactly `width` × `height`, 8-bit RGB; `Err` names what differs.
pub fn decode_rgb(bytes: &[u8], width: u32, height: u32) -> std::result::Result<Vec<u8>, String> {
    let expected = (width as usize) * (height as usize) * 3;
    // Room for the image and the decoder's own buffers, never more.
    let limits = png::Limits { bytes: expected.saturating_mul(4).max(1 << 16) };
    let decoder = png::Decoder::new_with_limits(std::io::Cursor::new(bytes), limits);
    let mut reader = decoder.read_info().map_err(|e| format!("not a readable PNG: {e}"))?;
    let info = reader.info();
    if (info.width, info.height) != (width, height)
        || info.color_type != png::ColorType::Rgb
        || info.bit_depth != png::BitDepth::Eight
    {
        return Err(format!(
            "PNG is {} × {} {:?} {:?}-bit; expected {width} × {height} 8-bit RGB",
            info.width, info.height, info.color_type, info.bit_depth as u8
        ));
    }
    let mut rgb = vec![0; expected];
    reader.next_frame(&mut rgb).map_err(|e| format!("PNG data: {e}"))?;
    Ok(rgb)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_round_trip_and_wrong_sizes_are_refused() {
        let rgb: Vec<u8> = (0..4 * 3 * 3).map(|i| (i * 7) as u8).collect();
        let bytes = encode_rgb(4, 3, &rgb).unwrap();
        assert_eq!(decode_rgb(&bytes, 4, 3).unwrap(), rgb);
        let e = decode_rgb(&bytes, 64, 64).unwrap_err();
        assert!(e.contains("expected 64 × 64"), "{e}");
        assert!(decode_rgb(&bytes[..bytes.len() / 2], 4, 3).is_err());
        assert!(decode_rgb(b"not a png", 4, 3).is_err());
        assert!(encode_rgb(4, 4, &rgb).is_err());
    }
}
