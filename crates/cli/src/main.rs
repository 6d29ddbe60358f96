//! `inbetween`: the command-line front end of every engine.

mod bench;
mod cmd_batch;
mod cmd_camera;
mod cmd_face;
mod cmd_io;
mod cmd_mocap;
mod cmd_preview;
mod cmd_script;
mod cmd_studio;
mod cmd_video;
mod demo;
mod errors;
mod scale;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

#[derive(Parser)]
#[command(
    name = "inbetween",
    version,
    about = "AI-assisted keyframe animation: in-betweening, keyframe extraction, previews"
)]
struct Cli {
    /// On an error, also print its backtrace (same as INBETWEEN_DEBUG=1).
    #[arg(long, global = true)]
    debug: bool,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Print a motion file's skeleton, frame count, rate, duration and channels.
    Info(cmd_io::InfoArgs),
    /// Convert ASF/AMC or BVH to BVH, optionally resampled and cropped.
    Convert(cmd_io::ConvertArgs),
    /// Render a motion file to an animated GIF (or a PNG of one frame).
    Preview(cmd_preview::PreviewArgs),
    /// Run the built-in demo on procedural data (no files needed) and write its outputs.
    Demo(demo::DemoArgs),
    /// Mocap engine: SIDQL keyframe extraction, reconstruction, codec, streaming, benchmark.
    #[command(subcommand)]
    Mocap(cmd_mocap::MocapCommand),
    /// Camera engine: style-aware camera in-betweening in Toric space.
    #[command(subcommand)]
    Camera(cmd_camera::CameraCommand),
    /// Face engine: blendshape animation editing by inpainting (BiLSTM GAN), guided by keys, a noisy take or visemes.
    #[command(subcommand)]
    Face(cmd_face::FaceCommand),
    /// Video engine: new frame orders from one clip (learned frame metric RSFNet + SDPF path finding).
    #[command(subcommand)]
    Video(cmd_video::VideoCommand),
    /// Script engine: text → semantic scene graph → furnished scene (Write-An-Animation).
    #[command(subcommand)]
    Script(cmd_script::ScriptCommand),
    /// Local web studio (script, mocap, camera, face and video panels): serves http://127.0.0.1:7878/ until Ctrl-C.
    Studio(cmd_studio::StudioArgs),
    /// One job over a whole folder, in shards for a cluster (Slurm job arrays, Kubernetes Indexed
    /// Jobs; Dask through the Python package): mocap-compress, mocap-keys, video-analyse,
    /// script-run, face-edit, and summary.
    #[command(subcommand)]
    Batch(cmd_batch::BatchCommand),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let debug = cli.debug || std::env::var_os("INBETWEEN_DEBUG").is_some_and(|v| v != "0");
    errors::install(debug);
    match dispatch(cli.command) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprint!("{}", errors::render(&e, debug));
            ExitCode::FAILURE
        }
    }
}

/// The CLI only parses arguments (above) and calls the engines' library functions (below).
fn dispatch(command: Command) -> anyhow::Result<()> {
    match command {
        Command::Info(a) => cmd_io::info(a),
        Command::Convert(a) => cmd_io::convert(a),
        Command::Preview(a) => cmd_preview::run(a),
        Command::Demo(a) => demo::run(a),
        Command::Mocap(c) => cmd_mocap::run(c),
        Command::Camera(c) => cmd_camera::run(c),
        Command::Face(c) => cmd_face::run(c),
        Command::Video(c) => cmd_video::run(c),
        Command::Script(c) => cmd_script::run(c),
        Command::Studio(a) => cmd_studio::run(a),
        Command::Batch(c) => cmd_batch::run(c),
    }
}
