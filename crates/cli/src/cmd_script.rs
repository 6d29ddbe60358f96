//! `inbetween script …`: text → semantic scene graph → furnished scene (Write-An-Animation §3–4.1).

use std::path::{Path, PathBuf};

use anyhow::Context;
use clap::{Args, Subcommand, ValueEnum};
use inbetween_io::Progress;

use crate::errors;
use inbetween_script::builtin_scripts;
use inbetween_script::compose::{ComposeConfig, Matcher};
use inbetween_script::jobs::{load_script, run_scene, RunJob, SceneJob};
use inbetween_script::limits::ScriptLimits;

#[derive(Subcommand)]
pub enum ScriptCommand {
    /// Compose the scene a script describes: scene.json, scene.gltf, ssg.json, top.png, view.png.
    Scene(SceneArgs),
    /// Scene + characters: animated glTF, BVH per character, preview GIF, routes PNG, cost curves.
    Run(RunArgs),
    /// Re-run `run` every time the script file is saved (the paper's editing loop).
    Watch(WatchArgs),
    /// Print the semantic scene graph of each sentence (JSON), and any problems found.
    Parse(ParseArgs),
    /// List the built-in scripts (paper captions, film lines, demo story) or print one.
    Stories(StoriesArgs),
    /// Parse/compose speed, matching scores (Fig. 8), layout violations and incremental edits.
    Bench(BenchArgs),
    /// `script run` on the demo story at 1×, 10×, 100× its directions (limits raised to fit):
    /// time and peak memory per run.
    Scale(crate::scale::ScaleArgs),
}

#[derive(Clone, Copy, ValueEnum)]
pub enum MatcherArg {
    /// Relation nodes first, single objects as the fallback (the paper's Algorithm 1).
    Relation,
    /// Single objects first (the LDS baseline).
    Object,
}

#[derive(Args)]
pub struct SceneArgs {
    /// Script file (plain text; scene sentences end in `$`). Use `builtin:NAME` for a built-in one
    /// (see `inbetween script stories`).
    pub script: String,
    /// Output folder.
    #[arg(short, long, default_value_os_t = SceneJob::default().out_dir)]
    pub out: PathBuf,
    #[arg(long, default_value_t = SceneJob::default().seed)]
    pub seed: u64,
    /// Camera of the perspective preview: front, back, left, right, top (default: the script's
    /// last "camera …" command, else front).
    #[arg(long)]
    pub view: Option<String>,
    /// Folder of Kenney furniture .glb files: real meshes and measured sizes instead of boxes
    /// (e.g. ../shared/data/assets/kenney_furniture).
    #[arg(long)]
    pub models: Option<PathBuf>,
    #[arg(long, value_enum, default_value = "relation")]
    pub matcher: MatcherArg,
    /// Only the objects the text names: do not furnish a named room from the database.
    #[arg(long)]
    pub bare: bool,
    /// Read words outside the synonym tables with the all-MiniLM-L6-v2 sentence-embedding model
    /// (needs a build with `--features embeddings` and scripts/fetch-minilm.sh).
    #[arg(long)]
    pub semantic: bool,
    /// Folder of the embedding model (default: ~/.cache/inbetween/models/all-MiniLM-L6-v2).
    #[arg(long, requires = "semantic")]
    pub model_dir: Option<PathBuf>,
    /// Most sentences the script may hold.
    #[arg(long, default_value_t = ScriptLimits::default().max_sentences)]
    pub max_sentences: usize,
    /// Most words the script may hold.
    #[arg(long, default_value_t = ScriptLimits::default().max_words)]
    pub max_words: usize,
    /// Most characters the script may name.
    #[arg(long, default_value_t = ScriptLimits::default().max_characters)]
    pub max_characters: usize,
    /// Most objects the scene sentences may ask for ("two chairs" counts 2).
    #[arg(long, default_value_t = ScriptLimits::default().max_objects)]
    pub max_objects: usize,
    /// Most character actions (verbs) the script may hold.
    #[arg(long, default_value_t = ScriptLimits::default().max_actions)]
    pub max_actions: usize,
    /// Longest animation, seconds, checked before any output is written.
    #[arg(long, default_value_t = ScriptLimits::default().max_animation_s)]
    pub max_animation_seconds: f64,
}

/// The limits' fields and the flags that raise them.
const LIMIT_FLAGS: &[(&str, &str)] = &[
    ("max_sentences", "--max-sentences"),
    ("max_words", "--max-words"),
    ("max_characters", "--max-characters"),
    ("max_objects", "--max-objects"),
    ("max_actions", "--max-actions"),
    ("max_animation_s", "--max-animation-seconds"),
];

#[derive(Args)]
pub struct RunArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// Skip the joint scene/motion optimisation (§4.3).
    #[arg(long)]
    pub no_optimize: bool,
    /// Use the CMU clips and Kenney animations of ../shared/data when present (default: the
    /// built-in procedural library).
    #[arg(long)]
    pub shared_motions: bool,
    /// Width of the preview GIF in pixels (at most 480).
    #[arg(long, default_value_t = RunJob::default().gif_width)]
    pub gif_width: u32,
    /// Also write story_skinned.gltf (+ story_skinned.png): every character as a skinned Kenney
    /// blocky character (found next to --models or in ../shared/data); story.gltf keeps the stick
    /// figures.
    #[arg(long)]
    pub skinned: bool,
    /// Stop after this many seconds of work; nothing is written then (the whole output set is
    /// moved into place only when the run finishes).
    #[arg(long)]
    pub time_limit: Option<f64>,
}

#[derive(Args)]
pub struct WatchArgs {
    #[command(flatten)]
    pub run: RunArgs,
    /// Stop after this many runs (default: until interrupted).
    #[arg(long)]
    pub max_runs: Option<usize>,
}

#[derive(Args)]
pub struct ParseArgs {
    /// Script file, or `builtin:NAME`.
    pub script: String,
}

#[derive(Args)]
pub struct StoriesArgs {
    /// Print this one instead of the list.
    pub name: Option<String>,
}

#[derive(Args)]
pub struct BenchArgs {
    #[arg(short, long, default_value = "out/script-bench")]
    pub out: PathBuf,
    #[arg(long, default_value_t = inbetween_script::bench::BenchConfig::default().seed)]
    pub seed: u64,
    /// Fewer timing repetitions (seconds).
    #[arg(long)]
    pub quick: bool,
}

pub fn run(c: ScriptCommand) -> anyhow::Result<()> {
    match c {
        ScriptCommand::Scene(a) => scene(a).map_err(|e| errors::name_flags(e, LIMIT_FLAGS)),
        ScriptCommand::Run(a) => run_story(a).map_err(|e| errors::name_flags(e, LIMIT_FLAGS)),
        ScriptCommand::Watch(a) => watch(a).map_err(|e| errors::name_flags(e, LIMIT_FLAGS)),
        ScriptCommand::Parse(a) => parse(a),
        ScriptCommand::Stories(a) => list_stories(a),
        ScriptCommand::Bench(a) => bench(a),
        ScriptCommand::Scale(a) => run_scale(a),
    }
}

fn scene_job(a: &SceneArgs) -> SceneJob {
    let matcher = match a.matcher {
        MatcherArg::Relation => Matcher::RelationFirst,
        MatcherArg::Object => Matcher::ObjectFirst,
    };
    SceneJob {
        out_dir: a.out.clone(),
        seed: a.seed,
        view: a.view.clone(),
        models: a.models.clone(),
        config: ComposeConfig { seed: a.seed, matcher, furnish: !a.bare },
        semantic: a.semantic.then(|| a.model_dir.clone()),
        limits: ScriptLimits {
            max_sentences: a.max_sentences,
            max_words: a.max_words,
            max_characters: a.max_characters,
            max_objects: a.max_objects,
            max_actions: a.max_actions,
            max_animation_s: a.max_animation_seconds,
        },
    }
}

fn run_job(a: &RunArgs) -> RunJob {
    RunJob {
        scene: scene_job(&a.scene),
        optimize: !a.no_optimize,
        shared_motions: a.shared_motions,
        gif_width: a.gif_width,
        cancel: Default::default(),
        progress: inbetween_io::Progress::hidden(),
    }
}

fn print_run(source: &Path, r: &inbetween_script::jobs::RunReport) {
    for d in &r.scene.diagnostics {
        eprintln!("warning: {}: {d}", source.display());
    }
    for n in &r.animation.notes {
        eprintln!("note: {}: {n}", source.display());
    }
    for line in r.summary(source) {
        println!("{line}");
    }
}

/// `script run`: the story's outputs appear in `--out` whole or not at all; `--skinned` outputs are
/// a second set, written after (a missing asset folder leaves the story's outputs in place).
fn run_story(a: RunArgs) -> anyhow::Result<()> {
    let (text, source) = load_script(&a.scene.script)?;
    let mut job = run_job(&a);
    job.cancel = errors::time_limit(a.time_limit)?;
    job.progress = Progress::new(0, "script run");
    let report = inbetween_script::jobs::run_story_whole(&text, &source, &job)
        .with_context(|| format!("animating {}", source.display()))?;
    print_run(&source, &report);
    if a.skinned {
        print_skinned(&a, &report)?;
    }
    Ok(())
}

/// `--skinned`: the skinned Kenney outputs beside the story's.
fn print_skinned(a: &RunArgs, r: &inbetween_script::jobs::RunReport) -> anyhow::Result<()> {
    let s = inbetween_script::jobs::write_skinned_whole(&a.scene.out, r, a.scene.models.as_deref())
        .context("writing the skinned characters")?;
    for n in &s.notes {
        println!("  {n}");
    }
    for f in &s.files {
        println!("  wrote {}", f.display());
    }
    Ok(())
}

fn watch(a: WatchArgs) -> anyhow::Result<()> {
    let path = PathBuf::from(&a.run.scene.script);
    println!("watching {} (Ctrl-C to stop)", path.display());
    inbetween_script::jobs::watch(&path, &run_job(&a.run), a.max_runs, |outcome| match outcome {
        Ok(r) => {
            print_run(&path, &r);
            if let Err(e) = a.run.skinned.then(|| print_skinned(&a.run, &r)).transpose() {
                eprintln!("error: {}: {e:#}", path.display());
            }
        }
        Err(e) => eprintln!("error: {}: {e}", path.display()),
    })
    .with_context(|| format!("watching {}", path.display()))?;
    Ok(())
}

fn scene(a: SceneArgs) -> anyhow::Result<()> {
    let (text, source) = load_script(&a.script)?;
    let job = scene_job(&a);
    let report = run_scene(&text, &source, &job).with_context(|| format!("composing {}", source.display()))?;
    for d in &report.diagnostics {
        eprintln!("warning: {}: {d}", source.display());
    }
    println!("{}", report.summary(&source));
    Ok(())
}

fn parse(a: ParseArgs) -> anyhow::Result<()> {
    let (text, source) = load_script(&a.script)?;
    let cat = inbetween_script::catalogue::builtin::builtin();
    let parsed = inbetween_script::parse::parse_script(&text, &cat);
    for s in &parsed.sentences {
        println!("# {} ({:?})", s.raw.at, s.raw.kind);
        println!("{}", serde_json::to_string_pretty(&s.ssg)?);
    }
    for d in &parsed.diagnostics {
        eprintln!("warning: {}: {d}", source.display());
    }
    Ok(())
}

fn list_stories(a: StoriesArgs) -> anyhow::Result<()> {
    let all = builtin_scripts::all();
    match a.name {
        Some(name) => {
            let (_, text) =
                all.iter().find(|(n, _)| *n == name).with_context(|| format!("no built-in script '{name}'"))?;
            println!("{text}");
        }
        None => {
            for (name, text) in &all {
                let first = text.lines().find(|l| !l.trim().is_empty()).unwrap_or("");
                println!("{name:<24} {first}");
            }
        }
    }
    Ok(())
}

fn bench(a: BenchArgs) -> anyhow::Result<()> {
    let opts = inbetween_io::report::BenchOptions {
        out: Some(a.out),
        quick: a.quick,
        seed: Some(a.seed),
        ..inbetween_io::report::BenchOptions::new(())
    };
    crate::bench::run("script bench", opts, inbetween_script::bench::run)?.print_files();
    Ok(())
}

fn run_scale(a: crate::scale::ScaleArgs) -> anyhow::Result<()> {
    // The demo story with its directions k times, the limits raised to fit (builtin_scripts).
    crate::scale::run(&a, "script", "script run at multiples of the demo story's directions", |k, exe, work| {
        let text = builtin_scripts::scaled_demo(k);
        let input = work.join(format!("story-{k}.txt"));
        std::fs::write(&input, &text).with_context(|| format!("writing {}", input.display()))?;
        let sentences = inbetween_script::sentences::split(&text).len();
        let l = builtin_scripts::scaled_demo_limits(k);
        let mut command = std::process::Command::new(exe);
        command.args(["script".as_ref(), "run".as_ref(), input.as_os_str(), "-o".as_ref()]);
        command.arg(work.join(format!("story-{k}"))).args(["--gif-width", "160"]);
        command.args(["--max-sentences", &l.max_sentences.to_string(), "--max-words", &l.max_words.to_string()]);
        command.args([
            "--max-actions",
            &l.max_actions.to_string(),
            "--max-animation-seconds",
            &l.max_animation_s.to_string(),
        ]);
        let input = format!("{sentences} sentences, {} actions", builtin_scripts::DEMO_ACTIONS * k);
        Ok(crate::scale::Measured { input, command })
    })
}
