//! The end of a campaign call: `runs.csv` sorted into the canonical order, then `summary.csv`,
//! `summary.md`, the charts and (with the `parquet` feature) `runs.parquet`.

use crate::error::CampaignError;
use crate::runs::{RUNS_FILE, RunRow, read_rows, rows_text, sorted_unique};
use crate::spec::{Campaign, RunKey};
use crate::stats::{GroupSummary, summarise, summary_csv, summary_md};
use std::path::Path;

/// Sorts `runs.csv` in place (atomically) and writes every derived file from it.
pub fn finish_dir(c: &Campaign, out: &Path) -> Result<Vec<GroupSummary>, CampaignError> {
    let path = out.join(RUNS_FILE);
    let existing = read_rows(&path)?;
    let rows = sorted_unique(c, existing.rows, &path)?;
    write_results(c, out, &rows)
}

/// Writes `runs.csv` (sorted) and everything derived from the rows.
pub fn write_results(
    c: &Campaign,
    out: &Path,
    rows: &[(RunKey, RunRow)],
) -> Result<Vec<GroupSummary>, CampaignError> {
    let write = |name: &str, bytes: &[u8]| {
        let p = out.join(name);
        plumetrace_mission::output::write_atomic(&p, bytes).map_err(|e| CampaignError::io(&p, e))
    };
    write(RUNS_FILE, rows_text(rows)?.as_bytes())?;
    // A call with fewer seeds than an earlier one into the same directory summarises its own
    // seeds; the runs of the others stay in runs.csv.
    let asked_for = |(k, _): &&(RunKey, RunRow)| k.seed_index < c.file.seeds;
    let asked: std::borrow::Cow<[(RunKey, RunRow)]> = if rows.iter().all(|r| asked_for(&r)) {
        rows.into()
    } else {
        rows.iter()
            .filter(asked_for)
            .cloned()
            .collect::<Vec<_>>()
            .into()
    };
    let beyond = rows.len() - asked.len();
    let groups = summarise(c, &asked);
    write("summary.csv", summary_csv(&groups).as_bytes())?;
    let expected = c.runs().len() as u64;
    let mut md = summary_md(c, &groups, expected);
    if beyond > 0 {
        md.push_str(&format!(
            "\n{beyond} more runs in `runs.csv`, of seeds beyond the {} per group this call asked \
             for (recorded by a call with more seeds), are left out of this summary and the \
             charts.\n",
            c.file.seeds
        ));
    }
    md.push_str(&crate::stats::sites_md(c, &asked));
    write("summary.md", md.as_bytes())?;
    crate::charts::write_charts(c, out, &groups, &asked)?;
    #[cfg(feature = "parquet")]
    crate::parquet_out::write_parquet(&out.join("runs.parquet"), rows)?;
    Ok(groups)
}
