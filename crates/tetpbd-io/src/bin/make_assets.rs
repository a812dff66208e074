//! Regenerates the sample surface meshes under `examples/assets/` (a torus and a bunny-like
//! blob, see `tetpbd_io::shapes`).
//!
//! `cargo run -p tetpbd-io --bin make_assets [-- DIR]` (default `examples/assets`, run from
//! the workspace root). The test `tests/assets.rs` checks the committed files match.

use std::path::PathBuf;

use tetpbd_io::shapes;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = PathBuf::from(
        std::env::args()
            .nth(1)
            .unwrap_or_else(|| "examples/assets".into()),
    );
    std::fs::create_dir_all(&dir)?;
    for (name, text) in shapes::sample_assets()? {
        let path = dir.join(name);
        std::fs::write(&path, text)?;
        println!("wrote {}", path.display());
    }
    Ok(())
}
