//! Writes the generated meshes of `bvhscope::mesh::generate::assets()` into `assets/`:
//! `cargo run --example make_assets`. `tests/shipped_scenes.rs` checks the committed files are
//! exactly what this writes, so run it (and commit the files) after changing a generator.
use std::path::Path;

fn main() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets");
    for (name, mesh) in bvhscope::mesh::generate::assets() {
        let path = dir.join(name);
        let mut text = Vec::new();
        bvhscope::mesh::write_obj(&mesh, &mut text).expect("writing to memory");
        std::fs::write(&path, &text).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        println!("wrote {}: {} triangles, {} KB", path.display(), mesh.triangle_count(), text.len() / 1024);
    }
}
