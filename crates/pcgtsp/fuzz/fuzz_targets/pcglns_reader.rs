//! Fuzz target: the instance and result readers must never panic, and whatever they accept must
//! be a consistent instance that survives the writer and the checker.
#![no_main]

use cutroute_pcgtsp::{check_tour, Instance, PcglnsResult};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let _ = PcglnsResult::parse(text);
    if let Ok(instance) = Instance::parse(text) {
        let n = instance.node_count;
        assert_eq!(instance.cost.len(), n * n);
        assert_eq!(instance.node_cluster.len(), n);
        assert!(instance.clusters.iter().all(|c| !c.is_empty()));
        let again = Instance::parse(&instance.to_pcglns()).expect("written instance must parse");
        assert_eq!(again.node_count, n);
        assert_eq!(again.clusters, instance.clusters);
        // The checker must answer (not panic) on an arbitrary node sequence.
        let tour: Vec<usize> = instance.clusters.iter().map(|c| c[0]).collect();
        let _ = check_tour(&instance, &tour);
    }
});
