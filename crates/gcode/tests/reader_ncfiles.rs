//! LinuxCNC's own example programs (the `ncfiles` its package ships, QtPlasmaC's among them):
//! every one that rs274 runs with motion in the sheet's plane reads as rs274 computes it
//! (pierces, cut length, idle length), and every one rs274 refuses is refused by the reader.
//! Programs that rs274 runs but the reader refuses (other planes, canned cycles, probing,
//! inverse-time feed, and compensated stretches the reader's model of LinuxCNC's compensation
//! does not follow) are counted, named and checked to be refused with a location.

mod reader_rs274;

use std::path::{Path, PathBuf};

use cutroute_gcode::{read_gcode, ReadOptions};

fn programs(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let path = entry.path();
        if path.is_dir() {
            programs(&path, out);
        } else if path.extension().is_some_and(|e| e == "ngc") {
            out.push(path);
        }
    }
}

#[test]
fn linuxcncs_example_programs_read_as_rs274_runs_them() {
    let Some(rs274) = reader_rs274::rs274() else {
        return;
    };
    let root = PathBuf::from(
        std::env::var("CUTROUTE_LINUXCNC_ROOT").unwrap_or(reader_rs274::LINUXCNC_ROOT.into()),
    );
    let mut files = Vec::new();
    programs(&root.join("usr/share/linuxcnc/ncfiles"), &mut files);
    files.sort();
    assert!(!files.is_empty(), "no ncfiles under {}", root.display());
    let (mut agree, mut both_refuse, mut beyond_2d) = (0, 0, Vec::new());
    // Of the programs read as rs274 runs them: with motion in the plane, and lacking a program
    // end (compared as if they had one).
    let (mut moving, mut endless) = (0, 0);
    let mut disagree = Vec::new();
    for path in &files {
        let name = path
            .strip_prefix(&root)
            .unwrap_or(path)
            .display()
            .to_string();
        let Ok(text) = std::fs::read_to_string(path) else {
            continue;
        };
        // `(print, …)` comments print to rs274's output, where they would read as errors.
        let quiet: String = text
            .lines()
            .map(|l| match l.to_ascii_lowercase().find("(print,") {
                Some(i) => format!("{}\n", &l[..i]),
                None => format!("{l}\n"),
            })
            .collect();
        let mut machine = reader_rs274::run(&rs274, &quiet, 1.0, false);
        // rs274 wants a program end; the reader does not (other controllers' programs and
        // subroutine files have none): a file lacking only that is compared as if it had one.
        if machine
            .error
            .as_ref()
            .is_some_and(|e| e.starts_with("File ended with no percent sign or program end"))
        {
            machine = reader_rs274::run(&rs274, &format!("{quiet}M2\n"), 1.0, false);
            endless += usize::from(machine.error.is_none());
        }
        // The harness's tool table holds every tool 1–9 with a radius of 1 mm.
        let options = ReadOptions {
            compensation_radius: Some(1.0),
            ..ReadOptions::default()
        };
        let read = read_gcode(&text, &options);
        match (&machine.error, read) {
            (Some(_), Err(_)) => both_refuse += 1,
            (None, Err(e)) => {
                let (line, column) = e.location();
                assert!(line >= 1 && column >= 1, "{name}: {e}");
                beyond_2d.push(format!("{name}: {e}"));
            }
            (Some(refusal), Ok(_)) => disagree.push(format!(
                "{name}: rs274 refuses ({refusal}), the reader reads it"
            )),
            (None, Ok(program)) => {
                // rs274 prints four decimals of the program's unit: of an inch, 2.54 µm.
                let inches = text.to_ascii_lowercase().contains("g20");
                let digit = if inches { 25.4e-4 } else { 1e-4 };
                let tolerance = 1e-3 + digit * program.motions.len() as f64;
                let same = machine.pierces.len() == program.pierce_count()
                    && machine
                        .pierces
                        .iter()
                        .zip(program.pierce_points())
                        .all(|(a, b)| a.distance(b) < 1e-3)
                    && (machine.cut - program.cut_length()).abs() < tolerance
                    && (machine.idle - program.idle_length()).abs() < tolerance;
                if same {
                    agree += 1;
                    moving += usize::from(!program.motions.is_empty());
                } else {
                    disagree.push(format!(
                        "{name}: rs274 {} pierces, cut {:.4}, idle {:.4}; read {}, {:.4}, {:.4}",
                        machine.pierces.len(),
                        machine.cut,
                        machine.idle,
                        program.pierce_count(),
                        program.cut_length(),
                        program.idle_length()
                    ));
                }
            }
        }
    }
    eprintln!(
        "{} ncfiles: {agree} read as rs274 runs them ({moving} with motion, {endless} without a program end), {both_refuse} refused by both, {} run by rs274 and refused by the reader:",
        files.len(),
        beyond_2d.len()
    );
    for b in &beyond_2d {
        eprintln!("  {b}");
    }
    assert!(
        disagree.is_empty(),
        "{} disagree with rs274:\n{}",
        disagree.len(),
        disagree.join("\n")
    );
    assert!(agree > 0, "no program was compared");
}
