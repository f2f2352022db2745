//! No file of the user's destroyed: an output that is an input is refused before any work, a
//! device or FIFO is written into and never replaced, a regular file is written whole and keeps
//! its permissions, and a failing standard output is an error exit with a message.

mod common;

use common::{cutroute, data};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("cutroute-output-files-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

fn s(path: &Path) -> &str {
    path.to_str().unwrap()
}

/// A copy of a shipped nest in the scratch folder, to be (not) overwritten.
fn nest_copy(name: &str) -> PathBuf {
    let copy = scratch(name);
    std::fs::copy(data("nests/dbs-json/E1X_6_01.dbs.json"), &copy).unwrap();
    copy
}

#[test]
fn an_output_that_is_the_input_is_refused_and_the_input_kept() {
    let nest = nest_copy("same.dbs.json");
    let before = std::fs::read(&nest).unwrap();
    let dotted = nest.parent().unwrap().join(".").join("same.dbs.json");
    let hard_link = scratch("same-hard-link.json");
    let _ = std::fs::remove_file(&hard_link);
    std::fs::hard_link(&nest, &hard_link).unwrap();
    let cases: Vec<Vec<&str>> = vec![
        vec!["convert", s(&nest), s(&nest), "--to", "html"],
        vec!["convert", s(&nest), s(&dotted), "--to", "json"],
        vec!["convert", s(&nest), s(&hard_link)],
        vec!["solve", s(&nest), "--solver", "nearest", "--out", s(&nest)],
        vec![
            "solve",
            s(&nest),
            "--solver",
            "nearest",
            "--out",
            s(&dotted),
        ],
    ];
    for args in cases {
        let (ok, stdout, stderr) = cutroute(&args);
        assert!(!ok, "{args:?} succeeded: {stdout}");
        assert!(
            stderr.contains("the output is the input"),
            "{args:?}: {stderr}"
        );
        assert_eq!(std::fs::read(&nest).unwrap(), before, "{args:?}");
    }
    // A profile or task file is an input too.
    let profile = scratch("profile.json");
    std::fs::write(&profile, r#"{"name": "p", "machine": {}}"#).unwrap();
    let (ok, _, stderr) = cutroute(&[
        "solve",
        s(&nest),
        "--solver",
        "nearest",
        "--profile",
        s(&profile),
        "--out",
        s(&profile),
    ]);
    assert!(
        !ok && stderr.contains("the output is the input"),
        "{stderr}"
    );
}

#[cfg(unix)]
#[test]
fn a_fifo_is_written_into_not_replaced() {
    use std::os::unix::fs::FileTypeExt;
    let nest = data("nests/dbs-json/E1X_6_01.dbs.json");
    let fifo = scratch("out.fifo");
    let _ = std::fs::remove_file(&fifo);
    let made = Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .expect("mkfifo runs");
    assert!(made.success());
    let reader = {
        let fifo = fifo.clone();
        std::thread::spawn(move || std::fs::read(fifo).unwrap())
    };
    let (ok, _, stderr) = cutroute(&["convert", s(&nest), s(&fifo), "--to", "json"]);
    assert!(ok, "{stderr}");
    let received = reader.join().unwrap();
    let kind = std::fs::symlink_metadata(&fifo).unwrap().file_type();
    assert!(kind.is_fifo(), "the FIFO was replaced by {kind:?}");
    let direct = scratch("direct.json");
    let (ok, _, stderr) = cutroute(&["convert", s(&nest), s(&direct), "--to", "json"]);
    assert!(ok, "{stderr}");
    assert_eq!(received, std::fs::read(&direct).unwrap());
}

#[cfg(unix)]
#[test]
fn devices_are_written_into_not_replaced() {
    use std::os::unix::fs::FileTypeExt;
    let nest = data("nests/dbs-json/E1X_6_01.dbs.json");
    // Through links in the scratch folder: the code path of `--out /dev/null` (the target is a
    // device), without any risk to the machine's own device files.
    for (device, succeeds) in [("/dev/null", true), ("/dev/full", false)] {
        if !Path::new(device).exists() {
            continue;
        }
        let link = scratch(&format!("link-to-{}", &device[5..]));
        let _ = std::fs::remove_file(&link);
        std::os::unix::fs::symlink(device, &link).unwrap();
        for args in [
            vec!["convert", s(&nest), s(&link), "--to", "svg"],
            vec!["solve", s(&nest), "--solver", "nearest", "--out", s(&link)],
        ] {
            let (ok, _, stderr) = cutroute(&args);
            assert_eq!(ok, succeeds, "{args:?}: {stderr}");
            if !succeeds {
                assert!(stderr.contains("incomplete"), "{args:?}: {stderr}");
                assert!(!stderr.contains("panicked"), "{stderr}");
            }
            let link_kind = std::fs::symlink_metadata(&link).unwrap().file_type();
            assert!(link_kind.is_symlink(), "{args:?}: the link was replaced");
            let target = std::fs::metadata(device).unwrap().file_type();
            assert!(target.is_char_device(), "{device} is no longer a device");
        }
    }
}

#[cfg(unix)]
#[test]
fn a_regular_file_keeps_its_permissions() {
    use std::os::unix::fs::PermissionsExt;
    let nest = data("nests/dbs-json/E1X_6_01.dbs.json");
    let out = scratch("kept-mode.svg");
    std::fs::write(&out, "old").unwrap();
    std::fs::set_permissions(&out, std::fs::Permissions::from_mode(0o640)).unwrap();
    let (ok, _, stderr) = cutroute(&["convert", s(&nest), s(&out)]);
    assert!(ok, "{stderr}");
    let mode = std::fs::metadata(&out).unwrap().permissions().mode() & 0o777;
    assert_eq!(mode, 0o640);
    assert!(std::fs::read_to_string(&out).unwrap().contains("<svg"));
}

#[test]
fn a_missing_folder_is_an_error_and_nothing_is_left() {
    let nest = data("nests/dbs-json/E1X_6_01.dbs.json");
    let out = scratch("no-such-folder").join("out.json");
    let (ok, _, stderr) = cutroute(&["convert", s(&nest), s(&out)]);
    assert!(!ok);
    assert!(stderr.contains("out.json"), "{stderr}");
    assert!(!out.parent().unwrap().exists());
}

/// Runs `cutroute ARGS` with standard output as `stdout`: (exit code, stderr).
fn with_stdout(args: &[&str], stdout: Stdio) -> (Option<i32>, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_cutroute"))
        .args(args)
        .stdout(stdout)
        .stderr(Stdio::piped())
        .output()
        .expect("runs");
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).into(),
    )
}

#[cfg(unix)]
#[test]
fn a_full_standard_output_is_an_error_exit_not_a_panic() {
    if !Path::new("/dev/full").exists() {
        return;
    }
    let nest = data("nests/dbs-json/E1X_6_01.dbs.json");
    for args in [
        vec!["inspect", s(&nest)],
        vec!["inspect", s(&nest), "--json"],
        vec!["solve", s(&nest), "--solver", "nearest"],
        vec!["convert", s(&nest), "-", "--to", "json"],
        vec!["generate", "--contours", "5", "--out", "-"],
    ] {
        let full = std::fs::OpenOptions::new()
            .write(true)
            .open("/dev/full")
            .unwrap();
        let (code, stderr) = with_stdout(&args, Stdio::from(full));
        assert_eq!(code, Some(1), "{args:?}: {stderr}");
        assert!(stderr.contains("standard output"), "{args:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
    }
}

#[cfg(unix)]
#[test]
fn a_closed_standard_output_is_an_error_exit() {
    let nest = data("nests/dbs-json/E1X_6_01.dbs.json");
    for args in [
        vec!["inspect", s(&nest), "--json"],
        vec!["solve", s(&nest), "--solver", "nearest"],
        vec!["convert", s(&nest), "-", "--to", "svg"],
    ] {
        // The shell closes descriptor 1 (`>&-`) and runs the binary.
        let out = Command::new("sh")
            .arg("-c")
            .arg("exec \"$0\" \"$@\" >&-")
            .arg(env!("CARGO_BIN_EXE_cutroute"))
            .args(&args)
            .stderr(Stdio::piped())
            .output()
            .expect("sh runs");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {stderr}");
        assert!(
            stderr.contains("standard output: it is closed"),
            "{args:?}: {stderr}"
        );
        // `> /dev/null` is a sink the user asked for: no error.
        let (code, stderr) = with_stdout(&args, Stdio::null());
        assert_eq!(code, Some(0), "{args:?}: {stderr}");
    }
}

#[cfg(unix)]
#[test]
fn a_reader_that_goes_away_is_an_error_exit() {
    // Far more than a pipe holds, so the write meets the closed pipe whenever it starts.
    let mut child = Command::new(env!("CARGO_BIN_EXE_cutroute"))
        .args(["generate", "--contours", "3000", "--out", "-"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("runs");
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("closed the pipe"), "{stderr}");
}
