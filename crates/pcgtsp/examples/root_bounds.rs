//! Prints the root bounds of every reference instance next to the known optimum.
use cutroute_pcgtsp::{root_bounds, Instance};
fn main() {
    let data =
        std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data/pcgtsp");
    for set in ["industrial", "pcgtsplib"] {
        let mut entries: Vec<_> = std::fs::read_dir(data.join(set))
            .unwrap()
            .map(|e| e.unwrap().path())
            .collect();
        entries.sort();
        for path in entries {
            let instance = Instance::parse(&std::fs::read_to_string(&path).unwrap()).unwrap();
            let t = std::time::Instant::now();
            let b = root_bounds(&instance).unwrap();
            println!(
                "{:<12} L1 {:>10.1} L2 {:>10.1}  {:?}",
                path.file_stem().unwrap().to_string_lossy(),
                b.l1,
                b.l2,
                t.elapsed()
            );
        }
    }
}
