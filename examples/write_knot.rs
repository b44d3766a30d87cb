//! Writes the benchmark's 2M-triangle knot as an OBJ (for profiling the loader):
//! `cargo run --release --example write_knot -- /tmp/knot2m.obj`
fn main() {
    let path = std::env::args().nth(1).unwrap_or_else(|| "knot2m.obj".into());
    let mut m = bvhscope::mesh::generate::torus_knot(3, 5, 0.12, 8192, 128);
    if std::env::args().any(|a| a == "--positions-only") {
        m.normals.clear();
        m.uvs.clear();
    }
    let mut f = std::io::BufWriter::new(std::fs::File::create(&path).expect("create"));
    bvhscope::mesh::write_obj(&m, &mut f).expect("write");
    println!("wrote {path}: {} triangles", m.triangle_count());
}
