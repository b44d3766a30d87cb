//! The closing ratio lines of a `versus` run: our best rows against each other implementation's
//! best, per ray set and thread count, the build rates and the memory per triangle.

use crate::contenders::Family;
use crate::Row;
use bvhscope::mesh::Mesh;
use std::fmt::Write;

fn best(rows: &[Row], pick: impl Fn(&Row) -> bool, key: impl Fn(&Row) -> f64) -> Option<&Row> {
    rows.iter().filter(|r| pick(r)).max_by(|a, b| key(a).total_cmp(&key(b)))
}

pub fn ratios(mesh: &Mesh, rows: &[Row]) -> String {
    let mut o = String::new();
    let name = mesh.name.split_whitespace().next().unwrap_or("mesh").to_lowercase();
    let ours = |r: &Row| r.family == Some(Family::Ours) && !r.name.contains("counting");
    let is = |f: Family| move |r: &Row| r.family == Some(f);
    let mut line = |label: &str, a: Option<&Row>, b: Option<&Row>, key: &dyn Fn(&Row) -> f64| {
        if let (Some(a), Some(b)) = (a, b) {
            let _ = writeln!(o, "ratio {label} {name}: {} / {} = {:.2}", a.name, b.name, key(a) / key(b));
        }
    };
    for (label, key) in [
        ("primary 1T", &(|r: &Row| r.p1) as &dyn Fn(&Row) -> f64),
        ("primary NT", &|r: &Row| r.pn),
        ("incoherent 1T", &|r: &Row| r.i1),
        ("incoherent NT", &|r: &Row| r.i_n),
    ] {
        // "best" may be a packet row; "best single-ray" leaves packets out, for comparing like
        // with like (obvhs and the bvh crate trace one ray at a time).
        let our_best = best(rows, ours, key);
        let single = |r: &Row| ours(r) && !r.name.contains("packets");
        let our_single = best(rows, single, key);
        for (what, a) in [("best", our_best), ("best single-ray", our_single)] {
            line(&format!("{label} {what}/obvhs-best-BVH2"), a, best(rows, is(Family::ObvhsBvh2), key), key);
            line(&format!("{label} {what}/obvhs-best-CWBVH"), a, best(rows, is(Family::ObvhsCwbvh), key), key);
        }
        // Against Embree: single rays with rtcIntersect1, and our best path with Embree's best
        // (packets and streams included).
        let embree_single = best(rows, is(Family::Embree), key);
        let embree_any = best(rows, |r| matches!(r.family, Some(Family::Embree | Family::EmbreePackets)), key);
        line(&format!("{label} best single-ray/embree-rtcIntersect1"), our_single, embree_single, key);
        line(&format!("{label} best/embree-best"), our_best, embree_any, key);
        let tinybvh = best(rows, is(Family::TinyBvh), key);
        line(&format!("{label} best single-ray/tinybvh-BVH8_CPU"), our_single, tinybvh, key);
        let fastest = rows.iter().find(|r| r.name == "bvhscope fastest (BVH8)");
        line(&format!("{label} fastest/embree-rtcIntersect1"), fastest, embree_single, key);
        line(&format!("{label} fastest/tinybvh-BVH8_CPU"), fastest, tinybvh, key);
        for our in ["bvhscope sah (BVH2)", "bvhscope sah (BVH2, 8×8 packets)"] {
            let a = rows.iter().find(|r| r.name == our);
            let label = format!("{label} sah-BVH2{}/bvh-crate", if our.contains("packets") { "-packets" } else { "" });
            line(&label, a, best(rows, is(Family::BvhCrate), key), key);
        }
    }
    let tris_per_s = |r: &Row| 1.0 / r.build_nt;
    let our_sah = rows.iter().find(|r| r.name == "bvhscope sah (BVH2)");
    let fastest = rows.iter().find(|r| r.name == "obvhs fastest (BVH2)");
    line("build NT triangles/s sah/obvhs-fastest", our_sah, fastest, &tris_per_s);
    let embree_medium = rows.iter().find(|r| r.name == "embree medium (rtcIntersect1)");
    for our_name in ["sah (BVH2)", "sah (BVH4)", "sah (BVH8)", "fastest (BVH8)"] {
        let our = rows.iter().find(|r| r.name == format!("bvhscope {our_name}"));
        let label = format!("build NT triangles/s {}/embree-medium", our_name.replace(" (", "-").replace(')', ""));
        line(&label, our, embree_medium, &tris_per_s);
    }
    let medium = rows.iter().find(|r| r.name == "obvhs medium (BVH2)");
    if let (Some(a), Some(b)) = (our_sah, medium) {
        let _ = writeln!(
            o,
            "SAH cost {name}: {} {:.2} vs {} {:.2}",
            a.name,
            a.sah.unwrap_or(f64::NAN),
            b.name,
            b.sah.unwrap_or(f64::NAN)
        );
    }
    let single_other = |r: &Row| matches!(r.family, Some(Family::Embree | Family::TinyBvh));
    for r in rows.iter().filter(|r| (ours(r) || single_other(r)) && !r.name.contains("packets")) {
        if let Some(b) = r.bytes {
            let what = match r.family {
                Some(Family::Embree) => "what the device allocates",
                Some(Family::TinyBvh) => "BVH8_CPU's nodes and four-triangle leaves",
                _ => "nodes + leaves",
            };
            let _ = writeln!(o, "memory {name}: {} {:.1} bytes per triangle ({what})", r.name, b);
        }
    }
    o
}
