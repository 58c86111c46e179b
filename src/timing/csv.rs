//! `--csv FILE`: one row per pass per frame, with the run's setup in every row so
//! files of several runs concatenate (minus their headers) into one table. The
//! work counters (`render --counters`) come last, empty when not counted.

use super::run::RunReport;

pub const HEADER: &str = "run_id,run,frame,warmup,pass,start_ns,duration_ns,clock,\
scene,environment,irradiance_resolution,kernel,chain,view,width,height,device,git_commit,\
input_vertices,input_primitives,vertex_invocations,clipping_invocations,clipping_primitives,\
fragment_invocations,compute_invocations";

/// RFC 4180 quoting where a field needs it.
pub fn field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

/// Empty for "not measured".
fn ns(v: Option<f64>) -> String {
    v.map_or(String::new(), |v| v.to_string())
}

pub fn csv(report: &RunReport) -> String {
    let s = &report.setup;
    let run = [
        field(&s.scene),
        field(&s.environment),
        s.irradiance_resolution.to_string(),
        field(&s.kernel),
        field(&s.chain),
        field(&s.view),
        report.width.to_string(),
        report.height.to_string(),
        field(&report.fingerprint.device),
        field(&report.git_commit),
    ]
    .join(",");
    let mut out = String::from(HEADER);
    out.push('\n');
    for f in &report.per_frame {
        for p in &f.passes {
            let counters = p.counters.map_or_else(
                || ",".repeat(6),
                |c| {
                    format!(
                        "{},{},{},{},{},{},{}",
                        c.input_vertices,
                        c.input_primitives,
                        c.vertex_invocations,
                        c.clipping_invocations,
                        c.clipping_primitives,
                        c.fragment_invocations,
                        c.compute_invocations
                    )
                },
            );
            out += &format!(
                "{},{},{},{},{},{},{},{},{run},{counters}\n",
                field(&report.run_id),
                f.run,
                f.frame,
                f.warmup,
                field(&p.name),
                ns(p.start_ns),
                ns(p.gpu_ns),
                field(&f.clock),
            );
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::super::run::{tests::report, GIT_COMMIT};
    use super::*;

    #[test]
    fn one_row_per_pass_per_frame() {
        let mut r = report(&[30.0, 10.0, 20.0]);
        r.per_frame[2].passes[1].gpu_ns = None;
        let text = csv(&r);
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines[0], HEADER);
        assert_eq!(lines.len(), 1 + 3 * 2);
        // The device name has a comma: quoted, so every row has the header's columns.
        assert_eq!(
            lines[3],
            format!(
                "{},0,1,false,a,10,10,host-fence,default,sky,256,deon7,full,final,64,48,\
                 \"test device, 2 cores\",{GIT_COMMIT},,,,,,,",
                r.run_id
            )
        );
        let columns = HEADER.split(',').count();
        // The device name's comma is inside quotes: one more piece per row.
        assert!(lines[1..]
            .iter()
            .all(|l| l.split(',').count() == columns + 1));
        let id = &r.run_id;
        assert!(
            lines[1].starts_with(&format!("{id},0,0,true,a,10,30,")),
            "{}",
            lines[1]
        );
        assert!(
            lines[6].starts_with(&format!("{id},0,2,false,b,30,,host-fence,")),
            "{}",
            lines[6]
        );
    }

    #[test]
    fn counters_fill_the_last_columns() {
        let mut r = report(&[30.0]);
        r.per_frame[0].passes[0].counters = Some(crate::timing::PassCounters::from_raw([
            3, 1, 3, 1, 2, 96, 0,
        ]));
        let text = csv(&r);
        let row = text.lines().nth(1).unwrap();
        assert!(row.ends_with(",3,1,3,1,2,96,0"), "{row}");
    }

    #[test]
    fn fields_are_quoted_when_they_must_be() {
        assert_eq!(field("blur_h"), "blur_h");
        assert_eq!(field("a,b"), "\"a,b\"");
        assert_eq!(field("say \"hi\""), "\"say \"\"hi\"\"\"");
    }
}
