//! `runs.parquet` (feature `parquet`): the sorted runs, the same columns as `runs.csv`, one row
//! group, Snappy compression. Missing numbers are nulls.

use crate::error::CampaignError;
use crate::runs::RunRow;
use crate::spec::RunKey;
use parquet::basic::Compression;
use parquet::data_type::{BoolType, ByteArray, ByteArrayType, DoubleType, Int32Type, Int64Type};
use parquet::file::properties::WriterProperties;
use parquet::file::writer::SerializedFileWriter;
use parquet::schema::parser::parse_message_type;
use std::path::Path;
use std::sync::Arc;

/// How a column is read from a row and stored.
#[derive(Clone, Copy)]
enum Col {
    /// Text (UTF-8).
    Text(fn(&RunRow) -> &str),
    /// An unsigned 64-bit whole number (stored as its bit pattern in INT64).
    U64(fn(&RunRow) -> u64),
    /// An unsigned 32-bit count.
    U32(fn(&RunRow) -> u32),
    /// A yes/no.
    Bool(fn(&RunRow) -> bool),
    /// An optional yes/no (null when missing).
    OptBool(fn(&RunRow) -> Option<bool>),
    /// An optional number (null when missing).
    Num(fn(&RunRow) -> Option<f64>),
}

/// Every column, in `runs.csv` order (a test compares the names with the CSV header).
const COLUMNS: &[(&str, Col)] = &[
    ("scenario", Col::Text(|r| &r.scenario)),
    ("config", Col::Text(|r| &r.config)),
    ("point", Col::Text(|r| &r.point)),
    ("seed_index", Col::U64(|r| r.seed_index)),
    ("seed", Col::U64(|r| r.seed)),
    ("outcome", Col::Text(|r| r.outcome.name())),
    ("success", Col::Bool(|r| r.success)),
    ("declared", Col::Bool(|r| r.declared)),
    ("declarations", Col::U32(|r| r.declarations)),
    ("sources", Col::U32(|r| r.sources)),
    ("sources_located", Col::U32(|r| r.sources_located)),
    ("declared_x", Col::Num(|r| r.declared_x)),
    ("declared_y", Col::Num(|r| r.declared_y)),
    ("source_x", Col::Num(|r| r.source_x)),
    ("source_y", Col::Num(|r| r.source_y)),
    ("error_m", Col::Num(|r| r.error_m)),
    ("error_along_m", Col::Num(|r| r.error_along_m)),
    ("error_cross_m", Col::Num(|r| r.error_cross_m)),
    ("first_detection_s", Col::Num(|r| r.first_detection_s)),
    ("declaration_s", Col::Num(|r| r.declaration_s)),
    ("path_length_m", Col::Num(|r| r.path_length_m)),
    ("trace_length_m", Col::Num(|r| r.trace_length_m)),
    (
        "detection_to_source_m",
        Col::Num(|r| r.detection_to_source_m),
    ),
    ("path_ratio", Col::Num(|r| r.path_ratio)),
    ("sim_time_s", Col::Num(|r| r.sim_time_s)),
    ("source_errors_m", Col::Text(|r| &r.source_errors_m)),
    ("longest_quiet_s", Col::Num(|r| r.longest_quiet_s)),
    ("max_outside_m", Col::Num(|r| r.max_outside_m)),
    ("team_converged_s", Col::Num(|r| r.team_converged_s)),
    (
        "team_range_error_median_m",
        Col::Num(|r| r.team_range_error_median_m),
    ),
    (
        "team_range_error_p90_m",
        Col::Num(|r| r.team_range_error_p90_m),
    ),
    (
        "team_range_setpoint_m",
        Col::Num(|r| r.team_range_setpoint_m),
    ),
    (
        "team_centroid_cross_median_m",
        Col::Num(|r| r.team_centroid_cross_median_m),
    ),
    (
        "team_distance_overhead",
        Col::Num(|r| r.team_distance_overhead),
    ),
    ("team_scale_max", Col::Num(|r| r.team_scale_max)),
    ("team_scale_final", Col::Num(|r| r.team_scale_final)),
    (
        "team_acoustic_lost",
        Col::Num(|r| r.team_acoustic_lost.map(|v| v as f64)),
    ),
    (
        "team_acoustic_delivered",
        Col::Num(|r| r.team_acoustic_delivered.map(|v| v as f64)),
    ),
    (
        "team_non_finite_commands",
        Col::Num(|r| r.team_non_finite_commands.map(|v| v as f64)),
    ),
    ("site_flow_toward_deg", Col::Num(|r| r.site_flow_toward_deg)),
    ("site_flow_speed_mps", Col::Num(|r| r.site_flow_speed_mps)),
    ("site_tidal_swing_deg", Col::Num(|r| r.site_tidal_swing_deg)),
    ("site_shape", Col::Text(|r| &r.site_shape)),
    (
        "site_flow_to_axis_deg",
        Col::Num(|r| r.site_flow_to_axis_deg),
    ),
    ("site_length_m", Col::Num(|r| r.site_length_m)),
    ("site_width_m", Col::Num(|r| r.site_width_m)),
    ("site_source_edge_m", Col::Num(|r| r.site_source_edge_m)),
    ("site_mass_rate_per_s", Col::Num(|r| r.site_mass_rate_per_s)),
    ("site_start", Col::Text(|r| &r.site_start)),
    ("site_fix_interval_s", Col::Num(|r| r.site_fix_interval_s)),
    ("site_fix_sigma_m", Col::Num(|r| r.site_fix_sigma_m)),
    ("site_flow_fault", Col::OptBool(|r| r.site_flow_fault)),
    ("message", Col::Text(|r| &r.message)),
];

fn schema() -> String {
    let mut s = String::from("message runs {\n");
    for (name, col) in COLUMNS {
        let line = match col {
            Col::Text(_) => format!("  REQUIRED BYTE_ARRAY {name} (UTF8);"),
            Col::U64(_) => format!("  REQUIRED INT64 {name} (INTEGER(64,false));"),
            Col::U32(_) => format!("  REQUIRED INT32 {name} (INTEGER(32,false));"),
            Col::Bool(_) => format!("  REQUIRED BOOLEAN {name};"),
            Col::OptBool(_) => format!("  OPTIONAL BOOLEAN {name};"),
            Col::Num(_) => format!("  OPTIONAL DOUBLE {name};"),
        };
        s.push_str(&line);
        s.push('\n');
    }
    s.push_str("}\n");
    s
}

/// Writes the rows (atomically: a temporary file, then a rename).
pub fn write_parquet(path: &Path, rows: &[(RunKey, RunRow)]) -> Result<(), CampaignError> {
    let fail = |e: &dyn std::fmt::Display| CampaignError::io(path, e);
    let schema = Arc::new(parse_message_type(&schema()).map_err(|e| fail(&e))?);
    let props = Arc::new(
        WriterProperties::builder()
            .set_compression(Compression::SNAPPY)
            .build(),
    );
    let tmp = path.with_extension("parquet.tmp");
    let file = std::fs::File::create(&tmp).map_err(|e| fail(&e))?;
    let mut writer = SerializedFileWriter::new(file, schema, props).map_err(|e| fail(&e))?;
    let rows: Vec<&RunRow> = rows.iter().map(|(_, r)| r).collect();
    let mut rg = writer.next_row_group().map_err(|e| fail(&e))?;
    let mut index = 0;
    while let Some(mut col) = rg.next_column().map_err(|e| fail(&e))? {
        let Some((_, kind)) = COLUMNS.get(index) else {
            return Err(fail(&"the schema has more columns than the column list"));
        };
        let written = match *kind {
            Col::Text(get) => col.typed::<ByteArrayType>().write_batch(
                &rows
                    .iter()
                    .map(|r| ByteArray::from(get(r)))
                    .collect::<Vec<_>>(),
                None,
                None,
            ),
            // Unsigned 64-bit values are stored as their two's-complement bit pattern.
            Col::U64(get) => col.typed::<Int64Type>().write_batch(
                &rows.iter().map(|r| get(r) as i64).collect::<Vec<_>>(),
                None,
                None,
            ),
            Col::U32(get) => col.typed::<Int32Type>().write_batch(
                &rows.iter().map(|r| get(r) as i32).collect::<Vec<_>>(),
                None,
                None,
            ),
            Col::Bool(get) => col.typed::<BoolType>().write_batch(
                &rows.iter().map(|r| get(r)).collect::<Vec<_>>(),
                None,
                None,
            ),
            Col::OptBool(get) => {
                let values: Vec<bool> = rows.iter().filter_map(|r| get(r)).collect();
                let levels: Vec<i16> = rows.iter().map(|r| i16::from(get(r).is_some())).collect();
                col.typed::<BoolType>()
                    .write_batch(&values, Some(&levels), None)
            }
            Col::Num(get) => {
                let values: Vec<f64> = rows.iter().filter_map(|r| get(r)).collect();
                let levels: Vec<i16> = rows.iter().map(|r| i16::from(get(r).is_some())).collect();
                col.typed::<DoubleType>()
                    .write_batch(&values, Some(&levels), None)
            }
        };
        written.map_err(|e| fail(&e))?;
        col.close().map_err(|e| fail(&e))?;
        index += 1;
    }
    rg.close().map_err(|e| fail(&e))?;
    writer.close().map_err(|e| fail(&e))?;
    std::fs::rename(&tmp, path).map_err(|e| fail(&e))
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;
    use parquet::file::reader::{FileReader, SerializedFileReader};
    use parquet::record::Field;

    fn row(seed_index: u64, error: Option<f64>) -> (RunKey, RunRow) {
        let key = RunKey {
            scenario: 0,
            config: 0,
            point: 0,
            seed_index,
        };
        let r = RunRow {
            scenario: "duck-2003-st".into(),
            config: "paper".into(),
            point: String::new(),
            seed_index,
            seed: u64::MAX - seed_index,
            outcome: crate::runs::RunOutcome::Mission(if error.is_some() {
                plumetrace_mission::Outcome::Declared
            } else {
                plumetrace_mission::Outcome::TimedOut
            }),
            success: error.is_some(),
            declared: error.is_some(),
            declarations: u32::from(error.is_some()),
            sources: 1,
            sources_located: u32::from(error.is_some()),
            declared_x: error,
            declared_y: error,
            source_x: Some(1.0),
            source_y: Some(2.0),
            error_m: error,
            error_along_m: error,
            error_cross_m: error,
            first_detection_s: Some(10.0),
            declaration_s: error,
            path_length_m: Some(100.0),
            trace_length_m: error,
            detection_to_source_m: Some(50.0),
            path_ratio: error,
            sim_time_s: Some(7200.0),
            source_errors_m: error.map_or(String::new(), |e| format!("{e:.3}")),
            site_flow_speed_mps: Some(0.25),
            site_shape: "convex".into(),
            site_flow_fault: error.map(|_| true),
            ..RunRow::default()
        };
        (key, r)
    }

    #[test]
    fn parquet_round_trips_values_and_nulls() {
        let tmp = std::env::temp_dir().join(format!("plumetrace-{}.parquet", std::process::id()));
        let rows = vec![row(0, Some(12.5)), row(1, None), row(2, Some(3.25))];
        write_parquet(&tmp, &rows).unwrap();
        let reader = SerializedFileReader::new(std::fs::File::open(&tmp).unwrap()).unwrap();
        assert_eq!(reader.metadata().file_metadata().num_rows(), 3);
        let read: Vec<_> = reader
            .get_row_iter(None)
            .unwrap()
            .map(|r| r.unwrap())
            .collect();
        let field = |r: &parquet::record::Row, name: &str| {
            r.get_column_iter()
                .find(|(n, _)| n.as_str() == name)
                .map(|(_, f)| f.clone())
                .unwrap()
        };
        assert_eq!(field(&read[0], "error_m"), Field::Double(12.5));
        assert_eq!(field(&read[1], "error_m"), Field::Null);
        assert_eq!(field(&read[2], "error_m"), Field::Double(3.25));
        assert_eq!(field(&read[1], "outcome"), Field::Str("timed_out".into()));
        assert_eq!(field(&read[2], "seed"), Field::ULong(u64::MAX - 2));
        assert_eq!(field(&read[0], "sources_located"), Field::UInt(1));
        assert_eq!(field(&read[1], "sources_located"), Field::UInt(0));
        assert_eq!(field(&read[0], "site_shape"), Field::Str("convex".into()));
        assert_eq!(field(&read[0], "site_flow_fault"), Field::Bool(true));
        assert_eq!(field(&read[1], "site_flow_fault"), Field::Null);
        assert_eq!(field(&read[1], "longest_quiet_s"), Field::Null);
        let names: Vec<String> = read[0].get_column_iter().map(|(n, _)| n.clone()).collect();
        assert_eq!(
            names.join(","),
            crate::runs::header(),
            "the same columns as runs.csv, in order"
        );
        std::fs::remove_file(&tmp).unwrap();
    }
}
