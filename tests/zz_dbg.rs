#[test]
fn dump() {
    let tp = feedopt::toolpath::apt::read(std::path::Path::new("/tmp/fz_apt1.cls")).unwrap();
    for (i, p) in tp.points.iter().enumerate() {
        if (25..=28).contains(&p.line) || (i > 0 && tp.points[i - 1].line == 27 && p.line != 27) {
            println!(
                "{i} line {} p {:?} o {:?} feed {:?}",
                p.line, p.p, p.o, p.feed
            );
        }
    }
}
