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
use plumetrace_mission::metrics::values_of;
use plumetrace_mission::{Column, ColumnKind, Value};
use std::path::Path;
use std::sync::Arc;

/// The Parquet schema of the columns of `runs.csv` ([`crate::runs::columns`]): text as UTF-8,
/// seeds and seed indices as unsigned 64-bit, counts as unsigned 32-bit, flags as booleans
/// (optional ones nullable), and optional numbers, whole ones included, as nullable doubles.
fn schema(columns: &[Column]) -> String {
    let mut s = String::from("message runs {\n");
    for c in columns {
        let name = c.name;
        let line = match c.kind {
            ColumnKind::Text => format!("  REQUIRED BYTE_ARRAY {name} (UTF8);"),
            ColumnKind::U64 => format!("  REQUIRED INT64 {name} (INTEGER(64,false));"),
            ColumnKind::U32 => format!("  REQUIRED INT32 {name} (INTEGER(32,false));"),
            ColumnKind::Bool => format!("  REQUIRED BOOLEAN {name};"),
            ColumnKind::OptBool => format!("  OPTIONAL BOOLEAN {name};"),
            ColumnKind::OptF64 | ColumnKind::OptU64 => format!("  OPTIONAL DOUBLE {name};"),
        };
        s.push_str(&line);
        s.push('\n');
    }
    s.push_str("}\n");
    s
}

/// A column's values as stored: the values present, and the definition levels of an optional
/// column (1 present, 0 null).
enum Stored {
    Text(Vec<ByteArray>),
    I64(Vec<i64>),
    I32(Vec<i32>),
    Bool(Vec<bool>, Option<Vec<i16>>),
    F64(Vec<f64>, Vec<i16>),
}

/// The values of column `index` of every row.
fn stored(kind: ColumnKind, rows: &[Vec<Value<'_>>], index: usize) -> Stored {
    let cells = rows.iter().map(|r| r[index]);
    let levels = |present: &dyn Fn(Value<'_>) -> bool| -> Vec<i16> {
        rows.iter().map(|r| i16::from(present(r[index]))).collect()
    };
    match kind {
        ColumnKind::Text => Stored::Text(
            cells
                .map(|v| match v {
                    Value::Text(t) => ByteArray::from(t),
                    _ => ByteArray::from(""),
                })
                .collect(),
        ),
        // Unsigned 64-bit values are stored as their two's-complement bit pattern.
        ColumnKind::U64 => Stored::I64(
            cells
                .map(|v| match v {
                    Value::U64(n) => n as i64,
                    _ => 0,
                })
                .collect(),
        ),
        ColumnKind::U32 => Stored::I32(
            cells
                .map(|v| match v {
                    Value::U32(n) => n as i32,
                    _ => 0,
                })
                .collect(),
        ),
        ColumnKind::Bool => Stored::Bool(
            cells.map(|v| matches!(v, Value::Bool(true))).collect(),
            None,
        ),
        ColumnKind::OptBool => Stored::Bool(
            cells
                .filter_map(|v| match v {
                    Value::OptBool(b) => b,
                    _ => None,
                })
                .collect(),
            Some(levels(&|v| matches!(v, Value::OptBool(Some(_))))),
        ),
        ColumnKind::OptF64 | ColumnKind::OptU64 => Stored::F64(
            cells.filter_map(number).collect(),
            levels(&|v| number(v).is_some()),
        ),
    }
}

/// An optional number, whole or not.
fn number(v: Value<'_>) -> Option<f64> {
    match v {
        Value::OptF64(x) => x,
        Value::OptU64(n) => n.map(|n| n as f64),
        _ => None,
    }
}

/// Writes the rows (atomically: a temporary file, then a rename).
pub fn write_parquet(path: &Path, rows: &[(RunKey, RunRow)]) -> Result<(), CampaignError> {
    let fail = |e: &dyn std::fmt::Display| CampaignError::io(path, e);
    let columns = crate::runs::columns();
    let schema = Arc::new(parse_message_type(&schema(&columns)).map_err(|e| fail(&e))?);
    let props = Arc::new(
        WriterProperties::builder()
            .set_compression(Compression::SNAPPY)
            .build(),
    );
    let tmp = path.with_extension("parquet.tmp");
    let file = std::fs::File::create(&tmp).map_err(|e| fail(&e))?;
    let mut writer = SerializedFileWriter::new(file, schema, props).map_err(|e| fail(&e))?;
    let values: Vec<Vec<Value<'_>>> = rows.iter().map(|(_, r)| values_of(r)).collect();
    let mut rg = writer.next_row_group().map_err(|e| fail(&e))?;
    let mut index = 0;
    while let Some(mut col) = rg.next_column().map_err(|e| fail(&e))? {
        let Some(column) = columns.get(index) else {
            return Err(fail(&"the schema has more columns than the column list"));
        };
        let written = match stored(column.kind, &values, index) {
            Stored::Text(v) => col.typed::<ByteArrayType>().write_batch(&v, None, None),
            Stored::I64(v) => col.typed::<Int64Type>().write_batch(&v, None, None),
            Stored::I32(v) => col.typed::<Int32Type>().write_batch(&v, None, None),
            Stored::Bool(v, levels) => {
                col.typed::<BoolType>()
                    .write_batch(&v, levels.as_deref(), None)
            }
            Stored::F64(v, levels) => {
                col.typed::<DoubleType>()
                    .write_batch(&v, Some(&levels), None)
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
    use crate::runs::SiteColumns;
    use parquet::file::reader::{FileReader, SerializedFileReader};
    use parquet::record::Field;
    use plumetrace_mission::RunMetrics;

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
            metrics: RunMetrics {
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
                team_acoustic_lost: error.map(|_| 4),
                ..RunMetrics::default()
            },
            site: SiteColumns {
                site_flow_speed_mps: Some(0.25),
                site_shape: "convex".into(),
                site_flow_fault: error.map(|_| true),
                ..SiteColumns::default()
            },
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
        assert_eq!(field(&read[0], "team_acoustic_lost"), Field::Double(4.0));
        assert_eq!(field(&read[1], "team_acoustic_lost"), Field::Null);
        assert_eq!(field(&read[0], "declared"), Field::Bool(true));
        let names: Vec<String> = read[0].get_column_iter().map(|(n, _)| n.clone()).collect();
        assert_eq!(
            names.join(","),
            crate::runs::header(),
            "the same columns as runs.csv, in order"
        );
        std::fs::remove_file(&tmp).unwrap();
    }
}
