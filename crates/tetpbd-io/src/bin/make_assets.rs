//! Regenerates the sample surface meshes under `examples/assets/` (a torus and a bunny-like
//! blob, see `tetpbd_io::shapes`).
//!
//! `cargo run -p tetpbd-io --features cli --bin make_assets [-- DIR]` (default
//! `examples/assets`, run from the workspace root). The test `tests/assets.rs` checks the committed files match.

use std::path::PathBuf;

use tetpbd_io::shapes;

/// Options of the command line.
#[derive(clap::Parser, Debug)]
#[command(about = "Regenerates the sample surface meshes (a torus and a bunny-like blob)")]
struct Options {
    /// The folder the meshes are written to (created if missing).
    #[arg(default_value = "examples/assets")]
    dir: PathBuf,
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = <Options as clap::Parser>::parse().dir;
    std::fs::create_dir_all(&dir)?;
    for (name, text) in shapes::sample_assets()? {
        let path = dir.join(name);
        std::fs::write(&path, text)?;
        println!("wrote {}", path.display());
    }
    Ok(())
}
