//! Tiles evenly spaced frames of a GIF into one PNG, to look at an animation as a still:
//! `cargo run -p inbetween-render --example gif_contact_sheet -- IN.gif OUT.png [FRAMES]`.

use image::AnimationDecoder;
use inbetween_render::Canvas;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    if args.len() < 3 {
        return Err("usage: gif_contact_sheet IN.gif OUT.png [FRAMES]".into());
    }
    let count: usize = args.get(3).map(|s| s.parse()).transpose()?.unwrap_or(8);
    let file = std::io::BufReader::new(std::fs::File::open(&args[1])?);
    let frames = image::codecs::gif::GifDecoder::new(file)?.into_frames().collect_frames()?;
    let picks: Vec<usize> = (0..count.min(frames.len())).map(|i| i * (frames.len() - 1) / (count.max(2) - 1)).collect();
    let (w, h) = frames[0].buffer().dimensions();
    let (tw, th) = (w / 2, h / 2);
    let cols = 4u32;
    let rows = (picks.len() as u32).div_ceil(cols);
    let mut sheet = Canvas::new(cols * tw, rows * th, [0, 0, 0]);
    for (k, &i) in picks.iter().enumerate() {
        let rgb = image::DynamicImage::ImageRgba8(frames[i].buffer().clone()).to_rgb8();
        let small = image::imageops::resize(&rgb, tw, th, image::imageops::FilterType::Triangle);
        sheet.blit(&small, (k as u32 % cols * tw) as i64, (k as u32 / cols * th) as i64);
        sheet.text(
            ((k as u32 % cols * tw) as f32 + 4.0, (k as u32 / cols * th) as f32 + 2.0),
            &format!("#{i}"),
            12.0,
            [200, 0, 0],
        );
    }
    inbetween_render::write_png(std::path::Path::new(&args[2]), &sheet.into_image())?;
    println!("{} frames in {}, sheet of {:?}", frames.len(), args[1], picks);
    Ok(())
}
