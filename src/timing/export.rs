//! What CI dashboards read: github-action-benchmark's `customSmallerIsBetter`
//! JSON and Bencher's Metric Format (BMF) from a run report, and a JUnit XML
//! summary of a comparison (one test case per pass, failed when regressed).

use super::regression::{Comparison, Verdict};
use super::run::RunReport;
use serde_json::{json, Value};

/// The key a benchmark's name is made of: the setup that changes the work,
/// so that dashboards keep runs of different setups apart.
fn prefix(r: &RunReport) -> String {
    let s = &r.setup;
    format!(
        "{} {}x{} irr{} {} {}",
        s.view, s.render_width, s.render_height, s.irradiance_resolution, s.kernel, s.chain
    )
}

/// github-action-benchmark (`tool: customSmallerIsBetter`): one entry per
/// measured pass, its median in ms; `range` the standard deviation, `extra`
/// the ruler multiple and the machine.
pub fn github_benchmark(r: &RunReport) -> Value {
    let key = prefix(r);
    let entries: Vec<Value> = r
        .passes
        .iter()
        .filter_map(|p| {
            let t = p.time?;
            let mut extra = format!(
                "{} frames; {} ({}), {} cores",
                p.frames, r.fingerprint.device, r.fingerprint.driver, r.fingerprint.cpu_cores
            );
            if let Some(x) = p.x_ruler {
                extra = format!("{x:.2} × ruler; {extra}");
            }
            Some(json!({
                "name": format!("{key} / {}", p.name),
                "unit": "ms",
                "value": t.median_ns / 1e6,
                "range": format!("± {:.3}", t.std_ns / 1e6),
                "extra": extra,
            }))
        })
        .collect();
    Value::Array(entries)
}

/// Bencher Metric Format: per pass, `latency` in ns (the median, with the
/// fastest and slowest frame as its bounds) and, where the ruler ran, an
/// `x-ruler` measure (ns/texel over the ruler's).
pub fn bencher(r: &RunReport) -> Value {
    let key = prefix(r);
    let mut out = serde_json::Map::new();
    for p in &r.passes {
        let Some(t) = p.time else { continue };
        let mut measures = serde_json::Map::new();
        measures.insert(
            "latency".into(),
            json!({ "value": t.median_ns, "lower_value": t.min_ns, "upper_value": t.max_ns }),
        );
        if let Some(x) = p.x_ruler {
            measures.insert("x-ruler".into(), json!({ "value": x }));
        }
        out.insert(format!("{key} / {}", p.name), Value::Object(measures));
    }
    Value::Object(out)
}

/// JUnit XML: a test suite per comparison (a sweep's point, or the one
/// comparison of two reports) of one test case per compared pass (rulers left
/// out), failed where it regressed; improved, unchanged and inconclusive passes
/// pass, with the verdict in their system-out.
pub fn junit(comparisons: &[&Comparison]) -> String {
    let judged = |c: &Comparison| c.passes.iter().filter(|p| p.judged).count();
    let failed = |c: &Comparison| c.count(Verdict::Regressed);
    let pct = |v: Option<f64>| v.map_or("n/a".to_string(), |v| format!("{:+.2}%", 100.0 * v));
    let mut s = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    s += &format!(
        "<testsuites name=\"dermis compare\" tests=\"{}\" failures=\"{}\">\n",
        comparisons.iter().map(|c| judged(c)).sum::<usize>(),
        comparisons.iter().map(|c| failed(c)).sum::<usize>()
    );
    for c in comparisons {
        s += &format!(
            "  <testsuite name=\"{}\" tests=\"{}\" failures=\"{}\">\n",
            xml(&format!("{} vs {}", c.base, c.new)),
            judged(c),
            failed(c)
        );
        for p in c.passes.iter().filter(|p| p.judged) {
            let summary = format!(
                "{}: change {} (95% CI [{}, {}]) in {} units, p = {:.3e} (Holm {:.3e}), {} vs {} {}s",
                p.verdict.name(),
                pct(p.change),
                pct(p.ci_low),
                pct(p.ci_high),
                p.unit,
                p.p,
                p.p_holm,
                p.base_samples,
                p.new_samples,
                p.sample
            );
            s += &format!(
                "    <testcase classname=\"dermis.passes\" name=\"{}\">\n",
                xml(&p.name)
            );
            if p.verdict == Verdict::Regressed {
                s += &format!(
                    "      <failure message=\"{}\" type=\"regression\"/>\n",
                    xml(&summary)
                );
            }
            s += &format!("      <system-out>{}</system-out>\n", xml(&summary));
            s += "    </testcase>\n";
        }
        s += "  </testsuite>\n";
    }
    s += "</testsuites>\n";
    s
}

fn xml(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
        .replace('\'', "&apos;")
}

#[cfg(test)]
mod tests {
    use super::super::regression::{compare, CompareOptions, MeasuredFrame, Measurement};
    use super::super::run::tests::report;
    use super::*;

    #[test]
    fn github_and_bencher_entries_per_pass() {
        let r = report(&[100.0, 2e6, 4e6, 3e6]);
        let g = github_benchmark(&r);
        assert_eq!(g.as_array().unwrap().len(), 2);
        assert_eq!(g[0]["unit"], "ms");
        assert_eq!(g[0]["value"], 3.0);
        assert!(g[0]["name"].as_str().unwrap().ends_with(" / a"));
        let b = bencher(&r);
        let a = b
            .as_object()
            .unwrap()
            .iter()
            .find(|(k, _)| k.ends_with("/ a"));
        let (_, a) = a.unwrap();
        assert_eq!(a["latency"]["value"], 3e6);
        assert_eq!(a["latency"]["lower_value"], 2e6);
        assert_eq!(a["latency"]["upper_value"], 4e6);
    }

    #[test]
    fn junit_fails_the_regressed_pass_only() {
        let side = |scale: f64, tag: &str| Measurement {
            source: format!("<{tag}>"),
            pass_order: vec!["blur & co".into(), "skin".into()],
            frames: (0..20)
                .map(|i| MeasuredFrame {
                    run: format!("r{}", i % 10),
                    passes: [
                        ("blur & co".to_string(), scale * (1000.0 + i as f64)),
                        ("skin".to_string(), 500.0 + i as f64),
                    ]
                    .into(),
                })
                .collect(),
            ..Default::default()
        };
        let c = compare(&side(1.0, "a"), &side(1.5, "b"), &CompareOptions::default()).unwrap();
        let x = junit(&[&c]);
        // blur and the frame's sum regressed, skin did not.
        assert!(x.contains("tests=\"3\" failures=\"2\""), "{x}");
        assert!(x.contains("&lt;a&gt; vs &lt;b&gt;"), "{x}");
        let case = |name: &str| {
            let at = x.find(&format!("name=\"{name}\"")).unwrap();
            x[at..].split("</testcase>").next().unwrap().to_string()
        };
        assert!(case("blur &amp; co").contains("<failure"), "{x}");
        assert!(!case("skin").contains("<failure"), "{x}");
        assert!(case("frame (sum of passes)").contains("<failure"), "{x}");
    }
}
