//! Reading regular grids from CSV files: numeric columns by header name and axis checks, shared by
//! the gridded flow and the gridded concentration.

use crate::EnvError;
use std::path::Path;

/// The numeric rows of a CSV file with a header: one `Vec` per row holding the `required` columns
/// then the `optional` ones (NaN where an optional column is absent); also which optional columns
/// were present. Every value must be a finite number; errors name the file, line and column.
pub(crate) fn read_columns(
    path: &Path,
    required: &[&str],
    optional: &[&str],
) -> Result<(Vec<Vec<f64>>, Vec<bool>), EnvError> {
    let file_err = |message: String| EnvError::File {
        path: path.to_path_buf(),
        message,
    };
    crate::input::check_file(path, crate::input::MAX_DATA_BYTES)
        .map_err(|e| file_err(e.to_string()))?;
    let mut reader = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .from_path(path)
        .map_err(|e| file_err(e.to_string()))?;
    let headers = reader
        .headers()
        .map_err(|e| file_err(e.to_string()))?
        .clone();
    let col = |name: &str| headers.iter().position(|h| h == name);
    let mut columns = Vec::new();
    for name in required {
        let Some(c) = col(name) else {
            return Err(file_err(format!(
                "header must name {} (optional: {}); found {:?}",
                required.join(", "),
                optional.join(", "),
                headers.iter().collect::<Vec<_>>()
            )));
        };
        columns.push((Some(c), *name));
    }
    let present: Vec<bool> = optional.iter().map(|n| col(n).is_some()).collect();
    columns.extend(optional.iter().map(|n| (col(n), *n)));
    let mut rows = Vec::new();
    for (k, rec) in reader.records().enumerate() {
        let line = k + 2;
        let rec = rec.map_err(|e| file_err(format!("line {line}: {e}")))?;
        let mut row = Vec::with_capacity(columns.len());
        for &(c, name) in &columns {
            let Some(c) = c else {
                row.push(f64::NAN);
                continue;
            };
            let s = rec.get(c).unwrap_or("");
            match s.parse::<f64>() {
                Ok(v) if v.is_finite() => row.push(v),
                _ => {
                    return Err(file_err(format!(
                        "line {line}: {name} = {s:?} is not a finite number"
                    )));
                }
            }
        }
        rows.push(row);
    }
    if rows.is_empty() {
        return Err(file_err("no data rows".into()));
    }
    Ok((rows, present))
}

/// The distinct values of a coordinate, checked to be evenly spaced: `(first, step, count)`.
pub(crate) fn regular_axis(
    values: impl Iterator<Item = f64>,
    name: &str,
    path: &Path,
) -> Result<(f64, f64, usize), EnvError> {
    let file_err = |message: String| EnvError::File {
        path: path.to_path_buf(),
        message,
    };
    let mut v: Vec<f64> = values.collect();
    v.sort_by(f64::total_cmp);
    v.dedup_by(|a, b| (*a - *b).abs() <= 1e-9 * (1.0 + b.abs()));
    if v.len() < 2 {
        return Err(file_err(format!(
            "column {name} needs at least 2 distinct values, found {}",
            v.len()
        )));
    }
    let step = (v[v.len() - 1] - v[0]) / (v.len() - 1) as f64;
    for (k, w) in v.iter().enumerate() {
        let expect = v[0] + k as f64 * step;
        if (w - expect).abs() > 1e-6 * step.abs().max(1.0) {
            return Err(file_err(format!(
                "column {name} is not evenly spaced: value {w} where {expect} was expected"
            )));
        }
    }
    Ok((v[0], step, v.len()))
}
