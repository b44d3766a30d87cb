//! Writes the meshes that BENCHMARKS.md's "EPO (issue 37)" section measures:
//! `cargo run --release --example write_epo_meshes -- needles /tmp/needles40k.obj 40000` (long thin
//! crossing triangles, `mesh::generate::needles`; an optional seed follows the count) and
//! `cargo run --release --example write_epo_meshes -- grid /tmp/grid4m.obj ../shared/models/stanford-bunny.obj 58`
//! (that many copies of a mesh side by side on a square grid, a little apart: 58 bunnies are
//! 4,028,158 triangles).
use bvhscope::mesh::{load_obj, write_obj};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let arg = |i: usize| args.get(i).map(String::as_str);
    let mesh = match arg(0) {
        Some("needles") => {
            let count = arg(2).map_or(40_000, |c| c.parse().expect("a count"));
            let seed = arg(3).map_or(37, |s| s.parse().expect("a seed"));
            bvhscope::mesh::generate::needles(count, seed)
        }
        Some("grid") => {
            let (one, _) = load_obj(arg(2).expect("the mesh to repeat")).expect("reading the mesh");
            bvhscope::mesh::generate::grid_of(&one, arg(3).map_or(58, |c| c.parse().expect("a count")))
        }
        _ => panic!("usage: write_epo_meshes needles PATH [COUNT [SEED]] | grid PATH MESH [COPIES]"),
    };
    let path = arg(1).expect("the output path");
    let mut f = std::io::BufWriter::new(std::fs::File::create(path).expect("create"));
    write_obj(&mesh, &mut f).expect("write");
    println!("wrote {path}: {} triangles", mesh.triangle_count());
}
