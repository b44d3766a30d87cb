//! The table as CSV (RFC 4180, by the `csv` crate), the GPU's rows after the CPU's when there are.

use super::gpu::GpuRow;
use super::rows::CompareRow;

fn opt(v: Option<f64>, digits: usize) -> String {
    v.map_or(String::new(), |v| format!("{v:.digits$}"))
}

const CSV_HEADER: [&str; 17] = [
    "strategy",
    "build_ms",
    "nodes",
    "max_depth",
    "mean_leaf_depth",
    "sah_cost",
    "epo",
    "epo_error",
    "nodes_per_ray",
    "tri_tests_per_ray",
    "root_box_nodes_per_ray",
    "root_box_tri_tests_per_ray",
    "trace_ms",
    "frame_ms",
    "mrays_per_s",
    "speedup_over_linear",
    "sampled_rays",
];

/// One row's CSV fields, in `CSV_HEADER`'s order.
fn csv_record(r: &CompareRow) -> Vec<String> {
    vec![
        r.name.clone(),
        opt(r.build_ms, 2),
        r.nodes.to_string(),
        r.max_depth.to_string(),
        format!("{:.2}", r.mean_leaf_depth),
        opt(r.sah_cost, 3),
        opt(r.epo, 3),
        opt(r.epo_error, 3),
        format!("{:.3}", r.nodes_per_ray),
        format!("{:.3}", r.tri_tests_per_ray),
        format!("{:.3}", r.root_nodes_per_ray),
        format!("{:.3}", r.root_tri_tests_per_ray),
        format!("{:.2}", r.trace_ms),
        format!("{:.2}", r.frame_ms),
        format!("{:.3}", r.mrays_per_s),
        format!("{:.1}", r.speedup_over_linear),
        r.sampled_rays.map_or(String::new(), |n| n.to_string()),
    ]
}

fn write_csv(records: Vec<Vec<String>>) -> String {
    let mut w = csv::Writer::from_writer(Vec::new());
    for rec in records {
        w.write_record(&rec).expect("writing CSV to memory");
    }
    String::from_utf8(w.into_inner().expect("writing CSV to memory")).expect("CSV of UTF-8 fields")
}

/// The rows as CSV (RFC 4180, by the `csv` crate): one header, one record per row; values not
/// measured (a linear scan's build time) are empty fields.
pub fn rows_csv(rows: &[CompareRow]) -> String {
    let mut records = vec![CSV_HEADER.map(String::from).to_vec()];
    records.extend(rows.iter().map(csv_record));
    write_csv(records)
}

/// `rows_csv` with the GPU's rows after the CPU's, in one table: five more columns say where a
/// row ran (device, node format, counted) and give its incoherent rays' time and MRays/s (empty
/// on the CPU's rows); a GPU row's trace and frame ms are its primary frame's GPU time.
pub fn rows_csv_with_gpu(rows: &[CompareRow], gpu: &[GpuRow]) -> String {
    let extra = ["device", "gpu_nodes", "counted", "incoherent_ms", "incoherent_mrays_per_s"];
    let mut records = vec![CSV_HEADER.iter().chain(&extra).map(|s| s.to_string()).collect::<Vec<_>>()];
    for r in rows {
        records.push(
            [csv_record(r), vec!["cpu".into(), String::new(), String::new(), String::new(), String::new()]].concat(),
        );
    }
    for g in gpu {
        let more = vec![
            "gpu".into(),
            g.gpu_nodes.name().to_string(),
            g.counted.to_string(),
            format!("{:.3}", g.incoherent_ms),
            format!("{:.3}", g.incoherent_mrays_per_s),
        ];
        records.push([csv_record(&g.row), more].concat());
    }
    write_csv(records)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(name: &str, build_ms: Option<f64>) -> CompareRow {
        CompareRow {
            name: name.into(),
            build_ms,
            nodes: 7,
            max_depth: 2,
            mean_leaf_depth: 1.5,
            sah_cost: build_ms.map(|_| 3.25),
            epo: build_ms.map(|_| 0.5),
            epo_error: None,
            nodes_per_ray: 1.0,
            tri_tests_per_ray: 2.0,
            root_nodes_per_ray: 4.0,
            root_tri_tests_per_ray: 8.0,
            trace_ms: 1.0,
            trace_runs: 5,
            frame_ms: 2.0,
            mrays_per_s: 3.0,
            speedup_over_linear: 4.0,
            sampled_rays: None,
            fallback_splits: 0,
        }
    }

    #[test]
    fn the_csv_has_as_many_fields_in_every_record_and_empty_ones_for_what_was_not_measured() {
        let text = rows_csv(&[row("Equal count, binary \"quoted\"", Some(1.0)), row("Linear scan", None)]);
        let mut r = csv::Reader::from_reader(text.as_bytes());
        let header = r.headers().unwrap().clone();
        let records: Vec<csv::StringRecord> = r.records().map(|r| r.unwrap()).collect();
        assert_eq!(records.len(), 2);
        for rec in &records {
            assert_eq!(rec.len(), header.len(), "{text}");
        }
        assert_eq!(&records[0][0], "Equal count, binary \"quoted\"");
        let build = header.iter().position(|h| h == "build_ms").unwrap();
        assert_eq!(&records[1][build], "", "the linear scan has no build");
        assert_eq!(&records[0][header.iter().position(|h| h == "root_box_nodes_per_ray").unwrap()], "4.000");
    }
}
