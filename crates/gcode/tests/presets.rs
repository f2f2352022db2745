//! Every post-processor preset's program of a real nest reads back through the project's
//! reader with the toolpath's lengths, pierces and dwell.

use std::path::PathBuf;

use cutroute_engine::{open_document, run_to_end, start_job};
use cutroute_gcode::{read_gcode, route_gcode, DwellFormat, GcodePreset, ReadOptions};
use cutroute_geometry::{MachineParameters, Toolpath};
use cutroute_protocol::{JobRequest, Problem, SolverKind, SolverParams};

#[test]
fn every_preset_reads_back_with_the_same_motion() {
    let relative = "nests/dbs/nested.dbs";
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../data")
        .join(relative);
    let bytes = std::fs::read(&path).expect("test nest");
    let document = open_document(relative, &bytes).expect("opens");
    let Problem::Nest { nest, .. } = &document.problem else {
        panic!("not a nest");
    };
    let request = JobRequest {
        job_id: 1,
        problem: document.problem.clone(),
        solver: SolverKind::NearestNeighbour,
        params: SolverParams::default(),
    };
    let mut job = start_job(&request).expect("starts");
    let route = run_to_end(job.as_mut(), &mut |_| {})
        .route()
        .cloned()
        .expect("a route");
    let toolpath = Toolpath::new(&route, nest).expect("toolpath");
    let machine = MachineParameters::default();
    for preset in GcodePreset::ALL {
        let options = preset.options(&machine);
        let text = route_gcode(nest, &route, &options).expect("writes");
        let read = ReadOptions {
            start: toolpath.start,
            ..preset.read_options()
        };
        let program = read_gcode(&text, &read).unwrap_or_else(|e| panic!("{preset}: {e}"));
        // Each written point moves by at most half a unit of the last digit in x and y.
        let quantum = 10f64.powi(-(options.decimals as i32));
        let tolerance = 2.0 * quantum * toolpath.moves.len() as f64;
        let what = preset.name();
        assert_eq!(
            program.pierce_count(),
            toolpath.pierce_count(),
            "{what}: pierces"
        );
        assert!(
            (program.cut_length() - toolpath.cut_length()).abs() <= tolerance,
            "{what}: cut {} vs {}",
            program.cut_length(),
            toolpath.cut_length()
        );
        assert!(
            (program.idle_length() - toolpath.idle_length()).abs() <= tolerance,
            "{what}: idle {} vs {}",
            program.idle_length(),
            toolpath.idle_length()
        );
        let dwell = match options.dwell_format {
            DwellFormat::Omitted => 0.0,
            _ => machine.pierce_time * toolpath.pierce_count() as f64,
        };
        assert!(
            (program.dwell_time() - dwell).abs() < 1e-6,
            "{what}: dwell {} vs {dwell}",
            program.dwell_time()
        );
        for line in options.header.iter().chain(&options.footer) {
            assert!(text.contains(line.as_str()), "{what}: {line:?} written");
        }
    }
}

#[test]
fn preset_names_parse_back() {
    for preset in GcodePreset::ALL {
        assert_eq!(preset.name().parse::<GcodePreset>(), Ok(preset));
    }
    assert!("haas".parse::<GcodePreset>().is_err());
}
