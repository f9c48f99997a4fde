//! `pfaff simulate --animate FILE.html`: one self-contained HTML file that plays the run.
//!
//! The file embeds the run in the JSON trajectory format (`pfaff::replay`, documented in
//! `docs/trajectory-format.md`) as the text of `<script type="application/json"
//! id="pfaff-trajectory">`, and a hand-written viewer (`animate.html`: canvas 2D, no
//! library, no network, no font) that draws it: planar models in 2-D, spatial ones with
//! an orbit camera. The URL fragment `#t=0.25` opens it paused at that time.

use std::path::Path;

use pfaff::replay::{Replay, ReplayOptions};
use pfaff::sim::Run;
use pfaff::Mechanism;
use serde_json::{Map, Value};

use super::error::CliError;

/// The viewer; `__TITLE__` and `__DATA__` are replaced.
const TEMPLATE: &str = include_str!("animate.html");

/// How the viewer samples: the default display rate, 7 significant digits.
pub fn options() -> ReplayOptions {
    ReplayOptions {
        digits: Some(7),
        ..ReplayOptions::default()
    }
}

/// The number of output intervals a run to `t_end` needs for the viewer, at least
/// `samples`.
pub fn grid(samples: usize, t_end: f64) -> usize {
    samples.max(options().samples(0.0, t_end))
}

/// Escapes JSON for the inside of a `<script>` element: `</` would end it, and `<!--`
/// would start a comment state; `\u003c` is the same JSON string.
fn escape_script(json: &str) -> String {
    json.replace('<', "\\u003c")
}

fn escape_html(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// The HTML file for `replay`.
pub fn html(replay: &Replay) -> String {
    TEMPLATE
        .replacen("__TITLE__", &escape_html(&replay.model.name), 1)
        .replacen("__DATA__", &escape_script(&replay.to_json()), 1)
}

/// The replay of `run`, decimated for the viewer, with `meta` describing the run.
pub fn replay(model: &dyn Mechanism, run: &Run, meta: Map<String, Value>) -> Replay {
    Replay::from_run(model, run, meta, &options())
}

/// Writes the HTML file of `run` to `path`.
pub fn write(
    model: &dyn Mechanism,
    run: &Run,
    meta: Map<String, Value>,
    path: &Path,
) -> Result<(), CliError> {
    let text = html(&replay(model, run, meta));
    super::out::write_file(path, |w| std::io::Write::write_all(w, text.as_bytes()))
}

/// The JSON embedded in an HTML file written by [`html`].
#[cfg(test)]
pub fn embedded(html: &str) -> Option<String> {
    let open = "<script type=\"application/json\" id=\"pfaff-trajectory\">";
    let start = html.find(open)? + open.len();
    let len = html[start..].find("</script>")?;
    Some(html[start..start + len].to_owned())
}

#[cfg(test)]
mod tests {
    use super::*;
    use pfaff::sim::{Method, Simulation};
    use pfaff_models::slider_crank_bodies;

    /// A run of 10⁵ output steps gives a file under 20 MB whose embedded JSON is the
    /// decimated trajectory, read back by the format's reader.
    #[test]
    fn a_run_of_1e5_steps_gives_a_file_under_20_mb() {
        let model = slider_crank_bodies::Model::default();
        let t_end = 20.0;
        let run = Simulation::new(&model)
            .integrator(Method::Dop853)
            .output_every(t_end / 1e5)
            .run(t_end)
            .expect("the slider-crank runs");
        assert!(run.trajectory.len() > 100_000, "{}", run.trajectory.len());
        let mut meta = Map::new();
        meta.insert("t_end".into(), t_end.into());
        let text = html(&replay(&model, &run, meta));
        assert!(text.len() < 20_000_000, "{} bytes", text.len());
        let json = embedded(&text).expect("the file embeds the trajectory");
        let back = Replay::from_json(&json).expect("the embedded JSON reads back");
        // The display grid, and the rows at events.
        let grid = options().samples(0.0, t_end);
        assert!(back.len() >= grid && back.len() <= grid + 2 * back.events.len());
        assert!(!back.drawing.shapes.is_empty());
        assert_eq!(back.times[0], 0.0);
        assert_eq!(*back.times.last().expect("samples"), t_end);
        assert!(!text.contains("http://") && !text.contains("https://"));
    }

    #[test]
    fn script_text_cannot_end_the_element() {
        let s = escape_script(r#"{"doc":"</script><!-- x"}"#);
        assert!(!s.contains("</") && !s.contains("<!--"));
        let v: Value = serde_json::from_str(&s).expect("still JSON");
        assert_eq!(v["doc"], "</script><!-- x");
    }
}
