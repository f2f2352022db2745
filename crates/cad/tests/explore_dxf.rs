use cutroute_cad::dxf::{read_dxf, DxfOptions};
#[test]
fn explore() {
    let dir = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../../shared/data/nests/dxf"
    );
    let mut names: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    names.sort();
    for p in names {
        let bytes = std::fs::read(&p).unwrap();
        let t = std::time::Instant::now();
        match read_dxf(&bytes, &DxfOptions::default()) {
            Ok(imp) => {
                println!(
                    "== {} ({:?}) parts={} open={} warnings={}",
                    p.display(),
                    t.elapsed(),
                    imp.nest.parts.len(),
                    imp.open_chains.len(),
                    imp.warnings.len()
                );
                for part in &imp.nest.parts {
                    let mut lo = (f64::MAX, f64::MAX);
                    let mut hi = (f64::MIN, f64::MIN);
                    for v in &part.contours[0].vertices {
                        lo.0 = lo.0.min(v.point.x);
                        lo.1 = lo.1.min(v.point.y);
                        hi.0 = hi.0.max(v.point.x);
                        hi.1 = hi.1.max(v.point.y);
                    }
                    let arcs: usize = part
                        .contours
                        .iter()
                        .map(|c| c.vertices.iter().filter(|v| v.bulge != 0.0).count())
                        .sum();
                    println!(
                        "  part {} contours={} verts={:?} arcs={} vbox=({:.3},{:.3})-({:.3},{:.3})",
                        part.name,
                        part.contours.len(),
                        part.contours
                            .iter()
                            .map(|c| c.vertices.len())
                            .collect::<Vec<_>>(),
                        arcs,
                        lo.0,
                        lo.1,
                        hi.0,
                        hi.1
                    );
                }
                for c in &imp.open_chains {
                    println!("  {c}");
                }
                for w in &imp.warnings {
                    println!("  W {w}");
                }
            }
            Err(e) => println!("== {} ERR {e}", p.display()),
        }
    }
}
