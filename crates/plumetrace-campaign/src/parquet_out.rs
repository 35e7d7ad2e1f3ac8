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

type Getter = fn(&RunRow) -> Option<f64>;
type CountGetter = fn(&RunRow) -> u32;

/// The count columns, in `runs.csv` order after `declared`.
const COUNTS: [(&str, CountGetter); 3] = [
    ("declarations", |r| r.declarations),
    ("sources", |r| r.sources),
    ("sources_located", |r| r.sources_located),
];

/// The optional numeric columns, in `runs.csv` order after the counts.
const NUMBERS: [(&str, Getter); 14] = [
    ("declared_x", |r| r.declared_x),
    ("declared_y", |r| r.declared_y),
    ("source_x", |r| r.source_x),
    ("source_y", |r| r.source_y),
    ("error_m", |r| r.error_m),
    ("error_along_m", |r| r.error_along_m),
    ("error_cross_m", |r| r.error_cross_m),
    ("first_detection_s", |r| r.first_detection_s),
    ("declaration_s", |r| r.declaration_s),
    ("path_length_m", |r| r.path_length_m),
    ("trace_length_m", |r| r.trace_length_m),
    ("detection_to_source_m", |r| r.detection_to_source_m),
    ("path_ratio", |r| r.path_ratio),
    ("sim_time_s", |r| r.sim_time_s),
];

fn schema() -> String {
    let mut s = String::from(
        "message runs {
  REQUIRED BYTE_ARRAY scenario (UTF8);
  REQUIRED BYTE_ARRAY config (UTF8);
  REQUIRED BYTE_ARRAY point (UTF8);
  REQUIRED INT64 seed_index (INTEGER(64,false));
  REQUIRED INT64 seed (INTEGER(64,false));
  REQUIRED BYTE_ARRAY outcome (UTF8);
  REQUIRED BOOLEAN success;
  REQUIRED BOOLEAN declared;
",
    );
    for (name, _) in COUNTS {
        s.push_str(&format!("  REQUIRED INT32 {name} (INTEGER(32,false));\n"));
    }
    for (name, _) in NUMBERS {
        s.push_str(&format!("  OPTIONAL DOUBLE {name};\n"));
    }
    s.push_str("  REQUIRED BYTE_ARRAY source_errors_m (UTF8);\n");
    s.push_str("  REQUIRED BYTE_ARRAY message (UTF8);\n}\n");
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
    let text = |f: fn(&RunRow) -> &str| -> Vec<ByteArray> {
        rows.iter().map(|r| ByteArray::from(f(r))).collect()
    };
    let mut rg = writer.next_row_group().map_err(|e| fail(&e))?;
    let mut index = 0;
    while let Some(mut col) = rg.next_column().map_err(|e| fail(&e))? {
        let written = match index {
            0 => col
                .typed::<ByteArrayType>()
                .write_batch(&text(|r| &r.scenario), None, None),
            1 => col
                .typed::<ByteArrayType>()
                .write_batch(&text(|r| &r.config), None, None),
            2 => col
                .typed::<ByteArrayType>()
                .write_batch(&text(|r| &r.point), None, None),
            3 => col.typed::<Int64Type>().write_batch(
                &rows.iter().map(|r| r.seed_index as i64).collect::<Vec<_>>(),
                None,
                None,
            ),
            // Unsigned 64-bit values are stored as their two's-complement bit pattern.
            4 => col.typed::<Int64Type>().write_batch(
                &rows.iter().map(|r| r.seed as i64).collect::<Vec<_>>(),
                None,
                None,
            ),
            5 => col
                .typed::<ByteArrayType>()
                .write_batch(&text(|r| r.outcome.name()), None, None),
            6 => col.typed::<BoolType>().write_batch(
                &rows.iter().map(|r| r.success).collect::<Vec<_>>(),
                None,
                None,
            ),
            7 => col.typed::<BoolType>().write_batch(
                &rows.iter().map(|r| r.declared).collect::<Vec<_>>(),
                None,
                None,
            ),
            i if i < 8 + COUNTS.len() => {
                let get = COUNTS[i - 8].1;
                col.typed::<Int32Type>().write_batch(
                    &rows.iter().map(|r| get(r) as i32).collect::<Vec<_>>(),
                    None,
                    None,
                )
            }
            i if i < 8 + COUNTS.len() + NUMBERS.len() => {
                let get = NUMBERS[i - 8 - COUNTS.len()].1;
                let values: Vec<f64> = rows.iter().filter_map(|r| get(r)).collect();
                let levels: Vec<i16> = rows.iter().map(|r| i16::from(get(r).is_some())).collect();
                col.typed::<DoubleType>()
                    .write_batch(&values, Some(&levels), None)
            }
            i if i == 8 + COUNTS.len() + NUMBERS.len() => {
                col.typed::<ByteArrayType>()
                    .write_batch(&text(|r| &r.source_errors_m), None, None)
            }
            _ => col
                .typed::<ByteArrayType>()
                .write_batch(&text(|r| &r.message), None, None),
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
            message: String::new(),
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
        let names: Vec<String> = read[0].get_column_iter().map(|(n, _)| n.clone()).collect();
        assert_eq!(
            names.join(","),
            crate::runs::header(),
            "the same columns as runs.csv, in order"
        );
        std::fs::remove_file(&tmp).unwrap();
    }
}
