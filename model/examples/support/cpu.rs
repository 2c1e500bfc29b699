//! CPU time of this process, for the speed examples (`#[path]`-included: examples share no crate).

/// CPU seconds of this process so far (all threads; Linux, 10 ms ticks), to measure on a shared
/// machine: the CPU time of many frames says more there than the wall time of the best.
pub fn cpu_secs() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let after = stat.rsplit(')').next().unwrap_or("");
    // Fields 14 and 15 of the file (utime, stime, in 1/100 s) are 11 and 12 after the name.
    let f: Vec<f64> = after
        .split_whitespace()
        .map(|x| x.parse().unwrap_or(0.0))
        .collect();
    f.get(11)
        .zip(f.get(12))
        .map_or(0.0, |(u, s)| (u + s) / 100.0)
}
