//! Shared helpers of the benchmark commands in `src/bin/` (each prints a Markdown table).
