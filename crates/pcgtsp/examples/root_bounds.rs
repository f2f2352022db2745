//! Prints the root bounds of every reference instance (L1, L2, and the cluster DP when the
//! order has at most 2 million ideals).
use cutroute_pcgtsp::{root_bounds, Instance};

fn main() {
    let data = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../data/pcgtsp");
    for set in ["industrial", "pcgtsplib"] {
        let mut entries: Vec<_> = std::fs::read_dir(data.join(set))
            .expect("data directory")
            .map(|e| e.expect("entry").path())
            .collect();
        entries.sort();
        for path in entries {
            let instance =
                Instance::parse(&std::fs::read_to_string(&path).expect("read")).expect("parse");
            let began = std::time::Instant::now();
            let b = root_bounds(&instance, 2_000_000).expect("valid order");
            println!(
                "{:<12} L1 {:>10.1} L2 {:>10.1} DP {:>12} {:?}",
                path.file_stem().unwrap_or_default().to_string_lossy(),
                b.l1,
                b.l2,
                b.cluster_dp.map_or("-".to_string(), |v| format!("{v:.1}")),
                began.elapsed()
            );
        }
    }
}
