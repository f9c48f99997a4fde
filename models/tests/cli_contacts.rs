//! Contacts in the `pfaff` binary: `list` counts them, `show` lists them with their
//! restitution parameter.

mod common;

use common::{pfaff, stdout};

#[test]
fn list_counts_contacts() {
    let out = pfaff(&["list"]);
    assert!(out.status.success());
    let text = stdout(&out);
    for (model, contacts) in [
        ("bouncing_ball", "1"),
        ("falling_rod", "2"),
        ("newtons_cradle", "2"),
        ("pendulum_floor", "1"),
        ("pendulum", "0"),
    ] {
        let line = text
            .lines()
            .find(|l| l.split_whitespace().next() == Some(model))
            .unwrap_or_else(|| panic!("`{model}` not listed"));
        let cols: Vec<&str> = line.split_whitespace().collect();
        assert_eq!(cols[4], contacts, "{line}");
    }
}

#[test]
fn show_lists_contacts() {
    let out = pfaff(&["show", "falling_rod"]);
    assert!(out.status.success());
    let text = stdout(&out);
    assert!(text.contains("contacts (2):"), "{text}");
    for name in ["lower_end", "upper_end"] {
        let line = text
            .lines()
            .find(|l| l.split_whitespace().next() == Some(name))
            .unwrap_or_else(|| panic!("`{name}` not shown in\n{text}"));
        assert!(line.contains("restitution e"), "{line}");
    }
    let text = stdout(&pfaff(&["show", "pendulum"]));
    assert!(text.contains("contacts (0):"), "{text}");
}

/// `simulate` reports the impacts: the summary lists them with the rest, `--json` has
/// `impacts` (time, contact, impulse, energy lost) and `contact_events`. The first
/// impact of the ball dropped from h = 1 is at √(2h/g) with the impulse (1 + e) m √(2gh).
#[test]
fn simulate_reports_impacts() {
    let out = pfaff(&["simulate", "bouncing_ball", "--t-end", "2", "--json"]);
    assert!(out.status.success());
    let v: serde_json::Value = serde_json::from_str(&stdout(&out)).expect("json");
    let impacts = v["impacts"].as_array().expect("impacts");
    assert!(impacts.len() > 10, "{}", impacts.len());
    let first = &impacts[0];
    assert_eq!(first["contact"], "floor");
    let t = first["t"].as_f64().unwrap();
    assert!((t - (2.0_f64 / 9.81).sqrt()).abs() < 1e-6, "{t}");
    let p = first["impulse"].as_f64().unwrap();
    assert!((p - 1.5 * (2.0_f64 * 9.81).sqrt()).abs() < 1e-5, "{p}");
    assert!(first["energy_lost"].as_f64().unwrap() > 0.0);
    let events = v["contact_events"].as_array().expect("events");
    assert_eq!(events[0]["kind"], "rest");
    let text = stdout(&pfaff(&["simulate", "bouncing_ball", "--t-end", "2"]));
    assert!(text.contains("impacts      "), "{text}");
    assert!(text.contains("floor comes to rest"), "{text}");
    let text = stdout(&pfaff(&["simulate", "pendulum"]));
    assert!(!text.contains("impacts"), "{text}");
}

/// `work-precision` on the impact models compares the final state after the impacts
/// with the closed forms (scene.rs): every adaptive method at rtol 1e-8 is within 1e-6.
#[test]
fn work_precision_on_impact_models() {
    for model in ["bouncing_ball", "falling_rod"] {
        let out = pfaff(&["work-precision", model]);
        assert!(out.status.success(), "{model}");
        let text = stdout(&out);
        assert!(text.contains("the closed-form solution"), "{text}");
        let mut checked = 0;
        for line in text.lines() {
            let cols: Vec<&str> = line.split_whitespace().collect();
            if cols.len() >= 4 && cols[1] != "rk4" && cols[2] == "1e-8" {
                let err: f64 = cols[3].parse().unwrap();
                assert!(err < 1e-6, "{model}: {line}");
                checked += 1;
            }
        }
        assert!(checked >= 9, "{model}: {checked} rows at 1e-8 in\n{text}");
    }
}

/// `work-precision` on the impact models also reports the error of the impact times
/// against their closed forms (`t_impact`: bouncing_ball t₁ = √(2h/g), t₂ = t₁(1 + 2e);
/// falling_rod t* = (v − speed)/g, scene.rs), and it falls with the tolerance: within
/// `rtol × span` on every row (the flights are polynomials, so the error is that of
/// the event location, tied to the tolerance).
#[test]
fn work_precision_reports_impact_time_errors() {
    for (model, span, impacts) in [("bouncing_ball", 1.0, 2), ("falling_rod", 0.08, 1)] {
        let out = pfaff(&["work-precision", model]);
        assert!(out.status.success(), "{model}");
        let text = stdout(&out);
        assert!(
            text.contains(&format!("over the {impacts} impacts of the span")),
            "{text}"
        );
        assert!(text.contains(" t_impact "), "{text}");
        let mut checked = 0;
        for line in text.lines() {
            let cols: Vec<&str> = line.split_whitespace().collect();
            if cols.len() < 5 || !["partitioning", "projection", "baumgarte"].contains(&cols[0]) {
                continue;
            }
            let rtol: f64 = cols[2].parse().unwrap();
            let err: f64 = cols[4].parse().unwrap();
            assert!(err <= rtol * span + 1e-15, "{model}: {line}");
            checked += 1;
        }
        assert_eq!(checked, 150, "{model}: rows in\n{text}");
    }
}
