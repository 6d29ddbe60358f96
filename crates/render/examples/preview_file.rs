//! One frame of a motion file as PNG, without the CLI:
//! `cargo run -p inbetween-render --example preview_file -- FILE OUT.png [FRAME]`.

use inbetween_render::stick::{render_motion_png, StickOptions};
use std::path::Path;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    if args.len() < 3 {
        return Err("usage: preview_file FILE OUT.png [FRAME]".into());
    }
    let frame: usize = args.get(3).map(|s| s.parse()).transpose()?.unwrap_or(0);
    let motion = inbetween_io::load_motion(Path::new(&args[1]))?;
    let opts =
        StickOptions { title: Some(args[1].rsplit('/').next().unwrap_or("").to_string()), ..StickOptions::default() };
    render_motion_png(Path::new(&args[2]), &[&motion], frame, &opts)?;
    println!("wrote {} (frame {frame} of {})", args[2], motion.num_frames());
    Ok(())
}
