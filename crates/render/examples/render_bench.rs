//! Prints the preview speed table: `cargo run -p inbetween-render --example render_bench [DIR]`.

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = std::env::args()
        .nth(1)
        .map(std::path::PathBuf::from)
        .unwrap_or_else(|| std::env::temp_dir().join("inbetween_render_bench"));
    std::fs::create_dir_all(&dir)?;
    let rows = inbetween_render::bench::render_bench(&dir, 3)?;
    print!("{}", inbetween_render::bench::table(&rows).to_text());
    println!("files in {}", dir.display());
    Ok(())
}
