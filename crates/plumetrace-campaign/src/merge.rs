//! `plumetrace merge`: shard directories of one campaign into one directory, as if run at once.

use crate::error::CampaignError;
use crate::example::EXAMPLES_DIR;
use crate::execute::{CAMPAIGN_COPY, META_FILE, Meta, write_meta};
use crate::finish::write_results;
use crate::runs::{RUNS_FILE, read_rows, sorted_unique};
use crate::spec::{Campaign, parse_campaign};
use std::path::{Path, PathBuf};

/// What a merge found.
#[derive(Debug, Clone, Default)]
pub struct MergeReport {
    /// Runs in the merged directory.
    pub runs: u64,
    /// Runs the campaign has in all.
    pub expected: u64,
    /// Shards whose last row was cut short (that run is missing; resume the shard).
    pub cut_partial_lines: Vec<PathBuf>,
}

fn read_meta(dir: &Path) -> Result<Meta, CampaignError> {
    let p = dir.join(META_FILE);
    let text = std::fs::read_to_string(&p).map_err(|e| {
        CampaignError::io(
            &p,
            format!("{e} (is {} a campaign directory?)", dir.display()),
        )
    })?;
    serde_json::from_str(&text).map_err(|e| CampaignError::Results {
        path: p.display().to_string(),
        line: Some(e.line() as u64),
        message: e.to_string(),
    })
}

/// Merges `dirs` into `out`: every input must hold the same campaign (equal fingerprints); a run
/// found in several inputs must have the same result in each. An `out` that already holds runs of
/// the same campaign is merged in too (nothing it holds is lost); an `out` that holds another
/// campaign, or other files, is refused.
pub fn merge(dirs: &[PathBuf], out: &Path) -> Result<MergeReport, CampaignError> {
    let Some(first) = dirs.first() else {
        return Err(CampaignError::Io {
            path: out.display().to_string(),
            message: "nothing to merge: name at least one directory".into(),
        });
    };
    let out_canon = std::fs::canonicalize(out).ok();
    let meta = read_meta(first)?;
    // What `out` holds already: nothing, or runs of this same campaign (merged in below).
    let mut dirs = dirs.to_vec();
    if out.is_dir() {
        if out.join(META_FILE).exists() {
            let held = read_meta(out)?;
            if held.fingerprint != meta.fingerprint {
                return Err(CampaignError::Results {
                    path: out.join(META_FILE).display().to_string(),
                    line: None,
                    message: format!(
                        "{} holds campaign '{}' ({}), not '{}' ({}): its results would be lost; \
                         merge into a new directory",
                        out.display(),
                        held.name,
                        held.fingerprint,
                        meta.name,
                        meta.fingerprint
                    ),
                });
            }
            if out.join(RUNS_FILE).exists() {
                dirs.push(out.to_path_buf());
            }
        } else {
            crate::execute::refuse_foreign(out)?;
        }
    }
    let dirs = &dirs[..];
    let mut seeds = 0;
    let mut campaign: Option<Campaign> = None;
    let mut all_rows = Vec::new();
    let mut report = MergeReport::default();
    for (k, d) in dirs.iter().enumerate() {
        // `out` may come last (its own runs, merged in), not among the inputs named.
        let is_out = out_canon.is_some() && std::fs::canonicalize(d).ok() == out_canon;
        if is_out && !(k + 1 == dirs.len() && d.as_path() == out) {
            return Err(CampaignError::Io {
                path: out.display().to_string(),
                message: "the output directory must not be one of the inputs".into(),
            });
        }
        let m = read_meta(d)?;
        if m.fingerprint != meta.fingerprint {
            return Err(CampaignError::Results {
                path: d.join(META_FILE).display().to_string(),
                line: None,
                message: format!(
                    "campaign '{}' (fingerprint {}) differs from '{}' in {} ({}): only shards \
                     of one campaign merge",
                    m.name,
                    m.fingerprint,
                    meta.name,
                    first.display(),
                    meta.fingerprint
                ),
            });
        }
        seeds = seeds.max(m.seeds);
        let copy = d.join(CAMPAIGN_COPY);
        let text = std::fs::read_to_string(&copy).map_err(|e| CampaignError::io(&copy, e))?;
        if campaign.is_none() {
            let file = parse_campaign(&text, &copy)?;
            campaign = Some(Campaign::resolve(file, &copy, text, false)?);
        }
        let existing = read_rows(&d.join(RUNS_FILE))?;
        if existing.cut_partial_line {
            report.cut_partial_lines.push(d.clone());
        }
        all_rows.extend(existing.rows);
    }
    let Some(mut c) = campaign else {
        return Err(CampaignError::Io {
            path: out.display().to_string(),
            message: "nothing to merge".into(),
        });
    };
    c.file.seeds = seeds.max(1);
    std::fs::create_dir_all(out.join(EXAMPLES_DIR))
        .map_err(|e| CampaignError::io(&out.join(EXAMPLES_DIR), e))?;
    write_meta(out, &Meta { seeds, ..meta }, &c.text)?;
    for d in dirs.iter().filter(|d| d.as_path() != out) {
        let Ok(entries) = std::fs::read_dir(d.join(EXAMPLES_DIR)) else {
            continue;
        };
        for entry in entries.flatten() {
            let target = out.join(EXAMPLES_DIR).join(entry.file_name());
            // The example runs and their replay pages.
            let known = entry
                .path()
                .extension()
                .is_some_and(|e| e == "json" || e == "html");
            if known && !target.exists() {
                std::fs::copy(entry.path(), &target).map_err(|e| CampaignError::io(&target, e))?;
            }
        }
    }
    let rows = sorted_unique(&c, all_rows, &out.join(RUNS_FILE))?;
    write_results(&c, out, &rows)?;
    report.runs = rows.len() as u64;
    report.expected = c.runs().len() as u64;
    Ok(report)
}
