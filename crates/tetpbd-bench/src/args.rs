//! Command-line helpers shared by the benchmark binaries.

/// The value after `name` on the command line parsed as a number, or `default`.
pub fn arg(name: &str, default: usize) -> usize {
    arg_str(name)
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

/// The value after `name` on the command line, if any.
pub fn arg_str(name: &str) -> Option<String> {
    let mut args = std::env::args().skip_while(|a| a != name);
    args.next()?;
    args.next()
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
