//! html — `DIR/report.html`: one self-contained page (inline CSS, no
//! scripts, no network) that links the SVG pictures written beside it
//! ([`super::plots`]), in the order a tyre engineer reads it: verdict and
//! explanation, the plots with a caption each (the verdict's own evidence
//! first), then the tables — the ranked candidates with their held-out
//! gain, BIC and NRMSE before/after, where the residual concentrates (the
//! locate statistics per channel), the quality tables in and out of sample
//! per condition.
//!
//! Must never: embed anything from outside the report directory, or let text
//! from a recording (file names, sources) through unescaped.

use super::plots::Plot;
use super::report::{Diagnosis, NrmseMap, QualityRow};
use serde_json::Value;
use std::fmt::Write;

/// HTML-escape `s`.
pub fn esc(s: &str) -> String {
    let mut o = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => o.push_str("&amp;"),
            '<' => o.push_str("&lt;"),
            '>' => o.push_str("&gt;"),
            '"' => o.push_str("&quot;"),
            '\'' => o.push_str("&#39;"),
            c => o.push(c),
        }
    }
    o
}

fn pct(v: f64) -> String {
    if v.is_finite() {
        format!("{:.2}", 100.0 * v)
    } else {
        "–".into()
    }
}

fn num(v: &Value) -> String {
    v.as_f64().map_or("–".into(), |x| {
        if x != 0.0 && (x.abs() < 1e-3 || x.abs() >= 1e5) {
            format!("{x:.4e}")
        } else {
            format!("{x:.4}")
        }
    })
}

fn quality_table(rows: &[QualityRow]) -> String {
    let mut s = String::from(
        "<table><tr><th>channel</th><th>condition</th><th>n</th><th>σ before %</th><th>σ after %</th><th>NRMSE before %</th><th>NRMSE after %</th></tr>\n",
    );
    for r in rows {
        let better = r.sigma_after < r.sigma_before - 1e-12;
        let _ = writeln!(
            s,
            "<tr{}><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td class=\"{}\">{}</td><td>{}</td><td>{}</td></tr>",
            if r.condition == "all" { " class=\"all\"" } else { "" },
            r.channel.name(),
            esc(&r.condition),
            r.n,
            pct(r.sigma_before),
            if better { "good" } else { "" },
            pct(r.sigma_after),
            pct(r.nrmse_before),
            pct(r.nrmse_after)
        );
    }
    s.push_str("</table>\n");
    s
}

/// The page. `baseline_note` says where the baseline came from (`--tir`
/// file or the fit and what it held).
pub fn page(d: &Diagnosis, plots: &[Plot], source: &str, baseline_note: &str) -> String {
    let mut s = String::new();
    let _ = write!(
        s,
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\
<title>tyrekit diagnosis: {v}</title>\n<style>\
body{{font-family:sans-serif;max-width:1200px;margin:2em auto;color:#222;line-height:1.4}}\
h1{{font-size:1.6em}} .verdict{{font-size:1.3em;padding:.6em 1em;background:#eef5ff;border-left:6px solid #1f77b4}}\
table{{border-collapse:collapse;margin:1em 0;font-size:.9em}} td,th{{border:1px solid #ccc;padding:3px 8px;text-align:right}}\
td:first-child,th:first-child,td:nth-child(2){{text-align:left}} tr.all{{font-weight:bold;background:#f6f6f6}}\
tr.sig{{background:#fff4e0}} td.good{{color:#080}} figure{{margin:1.5em 0}} img{{max-width:100%;border:1px solid #ddd}}\
figcaption{{font-size:.9em;color:#444}} details{{margin:1em 0}}\
</style></head><body>\n<h1>Diagnosis of {src}</h1>\n\
<p class=\"verdict\">Verdict: <b>{v}</b>{ev}</p>\n<p>{ex}</p>\n<p><small>{bn}</small></p>\n",
        v = esc(d.verdict()),
        ev = d
            .report
            .verdict_evidence
            .map_or(String::new(), |e| format!(" — evidence {}", esc(&e.in_words()))),
        src = esc(source),
        ex = esc(d.explanation()),
        bn = esc(baseline_note),
    );
    // Plots first, the verdict's own evidence leading (their order is
    // plots::draw_all's); the tables follow.
    s.push_str("<h2>Plots</h2>\n");
    for p in plots {
        let _ = writeln!(
            s,
            "<figure><a href=\"{f}\"><img src=\"{f}\" alt=\"{f}\"></a><figcaption>{c}</figcaption></figure>",
            f = esc(&p.file),
            c = esc(&p.caption)
        );
    }
    // Candidates.
    s.push_str("<h2>Candidates, ranked (verdict first)</h2>\n<table><tr><th>effect</th><th>held-out gain %</th><th>ΔBIC</th><th>parameters</th><th>NRMSE before (FX/FY/MZ) %</th><th>NRMSE after %</th><th>held-out NRMSE before → after (FY) %</th></tr>\n");
    let three = |v: &NrmseMap| {
        ["FX", "FY", "MZ"]
            .iter()
            .map(|k| v.get(k).copied().flatten().map_or("–".into(), pct))
            .collect::<Vec<_>>()
            .join(" / ")
    };
    let fy = |v: &NrmseMap| v.get("FY").copied().flatten().map_or("–".into(), pct);
    for e in &d.report.effects {
        let params = e
            .parameters
            .iter()
            .map(|(k, v)| format!("{} = {}", esc(k), num(&Value::from(*v))))
            .collect::<Vec<_>>()
            .join("<br>");
        let _ = writeln!(
            s,
            "<tr{}><td>{}</td><td>{}</td><td>{:+.1}</td><td>{}</td><td>{}</td><td>{}</td><td>{} → {}</td></tr>",
            if e.name == d.report.verdict { " class=\"all\"" } else { "" },
            esc(&e.name),
            pct(e.score),
            e.delta_bic,
            params,
            three(&e.nrmse_before),
            three(&e.nrmse_after),
            fy(&e.nrmse_before_held_out),
            fy(&e.nrmse_after_held_out),
        );
    }
    s.push_str("</table>\n<p><small>Held-out gain: share of the baseline's squared error (FX, FY, MZ, each over its variance) removed on the segments the candidate was not fitted on (the segments alternate between the halves within each group of kind and load); constant channel offsets are estimated on the fit half and removed. ΔBIC over the whole recording with one effective sample per recorded second (residuals stay correlated over a sweep): negative = the extra parameters pay for themselves.</small></p>\n");
    // Locate.
    let _ = writeln!(
        s,
        "<h2>Where the residual concentrates (baseline)</h2>\n<p><small>Each grouping: a statistic, its permutation p-value (segment-level groupings permute segments; sample-level ones shift each segment's residual circularly, keeping its autocorrelation), Holm-adjusted over the groupings of the channel; significant rows highlighted (family-wise 5 %). Size: the share of the channel's squared residual the grouping accounts for — significance says the structure is not noise, the size whether it matters (a named effect must remove {:.1} %).</small></p>",
        100.0 * super::candidate::MIN_GAIN
    );
    for (ch, f) in &d.findings {
        let _ = writeln!(
            s,
            "<h3>{}</h3>\n<table><tr><th>grouping</th><th>statistic</th><th>z</th><th>p</th><th>p (Holm)</th><th>size</th><th>detail</th></tr>",
            ch.name()
        );
        for x in f {
            let _ = writeln!(
                s,
                "<tr{}><td>{}</td><td>{:.4}</td><td>{:.1}</td><td>{:.4}</td><td>{:.4}</td><td>{}</td><td style=\"text-align:left\">{}</td></tr>",
                if x.significant { " class=\"sig\"" } else { "" },
                x.name,
                x.statistic,
                x.z,
                x.p_value,
                x.p_adjusted,
                if x.share.is_finite() {
                    format!("{:.2} %", 100.0 * x.share)
                } else {
                    "–".into()
                },
                esc(&x.detail)
            );
        }
        s.push_str("</table>\n");
    }
    // Quality.
    let _ = write!(
        s,
        "<h2>Fit before and after</h2>\n<p>σ = √(Σ(sim − test)²/Σ test²), NRMSE = RMS(sim − test)/range(test); \
before = baseline, after = {} model; each model's constant channel offset (sensor zero) estimated on the fit half and removed.</p>\n<h3>Out of sample (held-out segments)</h3>\n{}\
<details><summary>In sample (segments the candidates were fitted on)</summary>\n{}</details>\n",
        esc(d.verdict()),
        quality_table(&d.report.quality.out_of_sample),
        quality_table(&d.report.quality.in_sample)
    );
    s.push_str("<p><small>Files: diagnosis.json (machine-readable), baseline.tir, extended.tir (load in the FMU or <code>tyrekit replay --tir</code>).");
    if let Some(w) = d.report.extended_parameters_in_words() {
        let _ = write!(
            s,
            " extended.tir holds the verdict refitted on every segment once chosen (the table above shows the half fit that was scored): {}.",
            esc(&w)
        );
    }
    s.push_str("</small></p>\n</body></html>\n");
    s
}

#[cfg(test)]
mod tests {
    #[test]
    fn escapes_markup() {
        assert_eq!(
            super::esc("<a href='x'>&"),
            "&lt;a href=&#39;x&#39;&gt;&amp;"
        );
    }
}
