use tyrekit::data::*;
fn main() {
    let p = std::env::args().nth(1).unwrap();
    let mut o = LoadOptions::default();
    o.remove_warmup = false;
    let l = load(std::path::Path::new(&p), &o).unwrap();
    let r = &l.recording;
    for s in &r.segments {
        println!(
            "{:6} {:6} t {:8.2}-{:8.2} {:?} Fz {:7.1} γ {:6.4} P {:7.0} V {:5.2} a {:6.3}",
            s.start,
            s.end,
            r.samples[s.start].time,
            r.samples[s.end - 1].time,
            s.kind,
            s.fz,
            s.gamma,
            s.p,
            s.vx,
            s.alpha
        );
    }
    println!(
        "{} segments; report {:?}",
        r.segments.len(),
        l.report.warmup
    );
}
