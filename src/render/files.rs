//! Images to files: PNG, animated GIF, and a contact sheet of frames.

use std::path::Path;

use image::RgbaImage;

use crate::Error;

fn io_error(path: &Path, source: std::io::Error) -> Error {
    Error::Io { path: path.display().to_string(), source }
}

fn image_error(path: &Path, e: image::ImageError) -> Error {
    match e {
        image::ImageError::IoError(source) => io_error(path, source),
        other => io_error(path, std::io::Error::other(other)),
    }
}

/// Writes `img` as a PNG file, atomically (`output::AtomicFile`).
pub fn write_png(img: &RgbaImage, path: &Path) -> Result<(), Error> {
    let mut file = crate::output::AtomicFile::create(path)?;
    img.write_with_encoder(image::codecs::png::PngEncoder::new(file.writer())).map_err(|e| image_error(path, e))?;
    file.commit()
}

/// Writes `frames` (all of one size) as an animated GIF that loops forever,
/// each frame shown `frame_ms` milliseconds (GIF counts in hundredths of a
/// second: each frame's delay is rounded so that the frames together take
/// their whole time).
pub fn write_gif(frames: &[RgbaImage], frame_ms: f64, path: &Path) -> Result<(), Error> {
    let Some(first) = frames.first() else {
        return Err(Error::Input(format!("{}: no frames to write", path.display())));
    };
    if let Some(k) = frames.iter().position(|f| f.dimensions() != first.dimensions()) {
        return Err(Error::Input(format!(
            "{}: frame {k} is {:?} but frame 0 is {:?}; a GIF's frames share one size",
            path.display(),
            frames[k].dimensions(),
            first.dimensions()
        )));
    }
    let mut file = crate::output::AtomicFile::create(path)?;
    {
        // speed 10 of 1..30: the encoder's default balance of palette quality and time
        let mut encoder = image::codecs::gif::GifEncoder::new_with_speed(file.writer(), 10);
        encoder.set_repeat(image::codecs::gif::Repeat::Infinite).map_err(|e| image_error(path, e))?;
        // a GIF keeps delays in hundredths of a second: each frame's runs
        // to where the one after it starts, rounded, so the whole plays for
        // its frames' time (a delay of 33.3 ms rounded alone is 30 ms: 1 s
        // played in 0.9 s)
        let at = |k: usize| (k as f64 * frame_ms / 10.0).round() as u32;
        let delay = |k: usize| image::Delay::from_numer_denom_ms(10 * (at(k + 1) - at(k)), 1);
        encoder
            .encode_frames(frames.iter().enumerate().map(|(k, f)| image::Frame::from_parts(f.clone(), 0, 0, delay(k))))
            .map_err(|e| image_error(path, e))?;
    }
    file.commit()
}

/// `frames` tiled into one image, `columns` to a row in order, each scaled
/// to `tile_width` pixels wide if given (keeping its aspect), with a 2-pixel
/// white gutter. Frames of different sizes get cells of the largest.
pub fn contact_sheet(frames: &[RgbaImage], columns: u32, tile_width: Option<u32>) -> Result<RgbaImage, Error> {
    if frames.is_empty() || columns == 0 {
        return Err(Error::Input("contact sheet: needs at least one frame and one column".into()));
    }
    let scaled: Vec<std::borrow::Cow<RgbaImage>> = frames
        .iter()
        .map(|f| match tile_width {
            Some(w) if w > 0 && w != f.width() => {
                let h = ((f.height() as u64 * w as u64) / f.width() as u64).max(1) as u32;
                std::borrow::Cow::Owned(image::imageops::resize(f, w, h, image::imageops::FilterType::Triangle))
            }
            _ => std::borrow::Cow::Borrowed(f),
        })
        .collect();
    const GUTTER: u32 = 2;
    let cell_w = scaled.iter().map(|f| f.width()).max().unwrap_or(1);
    let cell_h = scaled.iter().map(|f| f.height()).max().unwrap_or(1);
    let columns = columns.min(frames.len() as u32);
    let rows = (frames.len() as u32).div_ceil(columns);
    let mut sheet = RgbaImage::from_pixel(
        columns * cell_w + (columns + 1) * GUTTER,
        rows * cell_h + (rows + 1) * GUTTER,
        image::Rgba([255, 255, 255, 255]),
    );
    for (k, f) in scaled.iter().enumerate() {
        let (col, row) = (k as u32 % columns, k as u32 / columns);
        let x = GUTTER + col * (cell_w + GUTTER);
        let y = GUTTER + row * (cell_h + GUTTER);
        image::imageops::replace(&mut sheet, f.as_ref(), x as i64, y as i64);
    }
    Ok(sheet)
}
