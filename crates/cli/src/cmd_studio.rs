//! `inbetween studio`: argument parsing only; the server and the bench live in `inbetween-studio`.

use std::net::{IpAddr, Ipv4Addr};
use std::path::PathBuf;
use std::sync::LazyLock;

use anyhow::Context;
use clap::{Args, Subcommand};
use inbetween_io::report::BenchOptions;
use inbetween_studio::bench::StudioBench;
use inbetween_studio::StudioConfig;

#[derive(Args)]
pub struct StudioArgs {
    #[command(subcommand)]
    pub command: Option<StudioCommand>,
    /// TCP port (0 picks a free one).
    #[arg(long, default_value_t = StudioConfig::default().port)]
    pub port: u16,
    /// Address to listen on. Default 127.0.0.1 (this machine only); another address exposes the
    /// studio to the network.
    #[arg(long)]
    pub listen: Option<IpAddr>,
    /// The only folder whose files the page may open by name (its BVH/AMC files are listed).
    /// Default: the shared data folder (../shared/data or $INBETWEEN_DATA) when present.
    #[arg(long)]
    pub root: Option<PathBuf>,
    /// Largest upload: a size with a unit (B, KB, MB, GB, KiB, MiB, GiB).
    #[arg(long, default_value = MAX_UPLOAD.as_str())]
    pub max_upload: String,
    /// Open the page in the system browser.
    #[arg(long)]
    pub open: bool,
}

/// The studio's upload limit, written as --max-upload takes it.
static MAX_UPLOAD: LazyLock<String> =
    LazyLock::new(|| inbetween_studio::server::format_size(StudioConfig::default().max_upload));

#[derive(Subcommand)]
pub enum StudioCommand {
    /// Drive headless Chromium through the panels and print the timing table (first paint,
    /// script edit to redraw, K change to redraw on a 1000-frame take, face span edit to redraw,
    /// memory); writes the table and PNG screenshots.
    Bench(BenchArgs),
}

#[derive(Args)]
pub struct BenchArgs {
    /// Output folder (table and screenshots).
    #[arg(short, long, default_value = "crates/studio/bench")]
    pub output: PathBuf,
    /// Repeats of each timed action (the table gives the median).
    #[arg(long, default_value_t = StudioBench::default().repeats)]
    pub repeats: usize,
}

pub fn run(a: StudioArgs) -> anyhow::Result<()> {
    match a.command {
        Some(StudioCommand::Bench(b)) => {
            let engine = StudioBench { repeats: b.repeats };
            let opts = BenchOptions { out: Some(b.output), ..BenchOptions::new(engine) };
            let done = crate::bench::run("studio bench", opts, inbetween_studio::bench::run).context("studio bench")?;
            println!("{}", done.report.to_text());
            Ok(())
        }
        None => serve(a),
    }
}

fn serve(a: StudioArgs) -> anyhow::Result<()> {
    let max_upload = inbetween_studio::server::parse_size(&a.max_upload).context("--max-upload")?;
    let root = match a.root {
        Some(r) => {
            anyhow::ensure!(r.is_dir(), "--root {}: not a folder", r.display());
            Some(r)
        }
        None => inbetween_io::shared_data_dir().ok(),
    };
    let config = StudioConfig {
        port: a.port,
        listen: a.listen.unwrap_or(IpAddr::V4(Ipv4Addr::LOCALHOST)),
        root,
        max_upload,
        ..StudioConfig::default()
    };
    let open = a.open;
    inbetween_studio::serve_until_ctrl_c(config, |url| {
        println!("studio: {url}");
        if open {
            if let Err(e) = inbetween_studio::server::open_browser(url) {
                eprintln!("warning: could not open a browser ({e}); open {url} yourself");
            }
        }
    })?;
    Ok(())
}
