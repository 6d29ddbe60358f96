//! ASF/AMC (Acclaim skeleton + motion) reader. Work in progress.

use crate::IoError;
use inbetween_core::Motion;
use std::path::{Path, PathBuf};

/// Parses an ASF skeleton and an AMC motion into a BVH-style [`Motion`].
pub fn parse_asf_amc(_asf_text: &str, _amc_text: &str, asf_name: &str, _amc_name: &str) -> Result<Motion, IoError> {
    Err(IoError::Invalid { file: asf_name.to_string(), line: 1, message: "ASF/AMC reading is not implemented yet".into() })
}

/// Reads an ASF skeleton file and an AMC motion file.
pub fn read_asf_amc(asf: &Path, amc: &Path) -> Result<Motion, IoError> {
    let asf_text = crate::read_text(asf)?;
    let amc_text = crate::read_text(amc)?;
    parse_asf_amc(&asf_text, &amc_text, &asf.display().to_string(), &amc.display().to_string())
}

/// The skeleton file for an AMC file: CMU naming (`01_01.amc` → `01.asf`) or the same stem.
pub(crate) fn find_asf_for(amc: &Path) -> Result<PathBuf, IoError> {
    let dir = amc.parent().unwrap_or(Path::new(""));
    let stem = amc.file_stem().and_then(|s| s.to_str()).unwrap_or("");
    let mut tried = Vec::new();
    if let Some((subject, _)) = stem.split_once('_') {
        tried.push(dir.join(format!("{subject}.asf")));
    }
    tried.push(dir.join(format!("{stem}.asf")));
    match tried.iter().find(|p| p.is_file()) {
        Some(p) => Ok(p.clone()),
        None => Err(IoError::MissingAsf { amc: amc.to_path_buf(), tried }),
    }
}
