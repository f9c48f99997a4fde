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
