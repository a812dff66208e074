//! Command-line helpers shared by the benchmark binaries.

/// The value after `name` on the command line parsed as a number, or `default`.
pub fn arg(name: &str, default: usize) -> usize {
    let args: Vec<String> = std::env::args().collect();
    args.iter()
        .position(|a| a == name)
        .and_then(|i| args.get(i + 1))
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

/// `true` when `name` is on the command line.
pub fn flag(name: &str) -> bool {
    std::env::args().any(|a| a == name)
}

/// The particle orders to measure, from `--spatial-order on|off|both` (default: the
/// builder's default, [`tetpbd::SoftBodyBuilder::DEFAULT_SPATIAL_ORDER`]).
pub fn orders() -> Vec<bool> {
    let args: Vec<String> = std::env::args().collect();
    let value = args
        .iter()
        .position(|a| a == "--spatial-order")
        .and_then(|i| args.get(i + 1));
    match value.map(String::as_str) {
        Some("on") => vec![true],
        Some("off") => vec![false],
        Some("both") => vec![false, true],
        _ => vec![tetpbd::SoftBodyBuilder::DEFAULT_SPATIAL_ORDER],
    }
}
