//! Writes the weights card (`inbetween_nn::weights`) of weights saved with a training summary
//! beside them (a `camera train` checkpoint, or weights from before cards existed):
//! `cargo run -p inbetween-camera --example weights_card -- WEIGHTS.bpk [CARD.json]`.
//! The style codes are computed here, once, from the weights ([`FastModel::behaviour_styles`]);
//! CARD defaults to WEIGHTS with `.json` (replacing the summary there).

use inbetween_camera::infer::FastModel;
use inbetween_camera::train::TrainSummary;
use std::path::PathBuf;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let weights = PathBuf::from(args.first().ok_or("usage: weights_card WEIGHTS.bpk [CARD.json]")?);
    let out = args.get(1).map_or_else(|| weights.with_extension("json"), PathBuf::from);
    let summary: TrainSummary = inbetween_camera::read_json(&weights.with_extension("json"))?;
    let model: FastModel = inbetween_camera::weights::load(&weights)?.model;
    let card = inbetween_camera::weights::card(&summary, &model)?;
    let json = serde_json::to_string_pretty(&card)? + "\n";
    inbetween_io::write_atomic(&out, json.as_bytes())?;
    println!("wrote {} ({} style codes)", out.display(), card.extra["style_codes"].as_array().map_or(0, |a| a.len()));
    Ok(())
}
