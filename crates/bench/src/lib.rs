//! Shared helpers of the benchmark commands in `src/bin/` (each prints a Markdown table for
//! `BENCHMARKS.md`): reading `reference.csv`, and CPU clocks for shared machines.
//!
//! ```
//! assert_eq!(cutroute_bench::csv_fields(r#"a,"1,2",b"#), ["a", "1,2", "b"]);
//! ```
#![deny(missing_docs)]

/// Splits a CSV line, honouring double quotes (the tour column of `reference.csv` holds commas).
pub fn csv_fields(line: &str) -> Vec<String> {
    let mut fields = Vec::new();
    let mut field = String::new();
    let mut quoted = false;
    for ch in line.chars() {
        match ch {
            '"' => quoted = !quoted,
            ',' if !quoted => fields.push(std::mem::take(&mut field)),
            _ => field.push(ch),
        }
    }
    fields.push(field);
    fields
}

/// CPU time (user + system) in seconds of a `/proc` stat file (`NaN` where there is none):
/// benchmark machines are often shared, so CPU time is reported beside wall time.
fn proc_cpu_seconds(stat_path: &str) -> f64 {
    std::fs::read_to_string(stat_path)
        .ok()
        .and_then(|stat| {
            // Fields 14 and 15 of stat(5), counted after the parenthesised name.
            let after = stat.rsplit_once(')')?.1;
            let fields: Vec<&str> = after.split_whitespace().collect();
            let user: f64 = fields.get(11)?.parse().ok()?;
            let system: f64 = fields.get(12)?.parse().ok()?;
            Some((user + system) / 100.0)
        })
        .unwrap_or(f64::NAN)
}

/// CPU seconds used by this process so far.
pub fn process_cpu_seconds() -> f64 {
    proc_cpu_seconds("/proc/self/stat")
}

/// CPU seconds used by the calling thread so far.
pub fn thread_cpu_seconds() -> f64 {
    proc_cpu_seconds("/proc/thread-self/stat")
}
