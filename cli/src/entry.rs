//! A model as the program knows it: an [`Entry`], built by [`model!`](crate::model) or
//! [`Entry::new`], carrying what the commands use beyond the model's own `Info` (its
//! [`Scene`]: a default span, a steady motion to linearize about, a closed form for
//! `work-precision`) and optionally its source for `show --code`.
//!
//! Every part but the name and the constructor has a default, so a model with nothing
//! but `model!(my_model)` gets every command: a 1 s span, no steady motion (linearized
//! about its initial state), and a high-accuracy run as the reference of
//! `work-precision`.

use pfaff::Mechanism;

use crate::scene::{ClosedForm, ImpactTimes, Scene, Steady};

/// One model of the program: how to build it and what the commands know about it.
#[derive(Clone, Copy, Debug)]
pub struct Entry {
    /// The model's name on the command line (its module name, and `Info::name`).
    pub name: &'static str,
    /// One line saying what the model is; empty for the first line of the model's doc
    /// comment (`Info::doc`).
    pub summary: &'static str,
    /// Builds the model with its default parameters.
    pub make: fn() -> Box<dyn Mechanism>,
    /// Stiff (elastic modes far above the motion's frequencies): the command simulates
    /// it with Radau5 by default and sweeps only Radau5 in `work-precision`, whose
    /// reference is a Radau5 run; explicit methods are held to their stability limit.
    pub stiff: bool,
    /// Default span, steady motion, closed form.
    pub scene: Scene,
    /// The Rust source holding the model's `#[pfaff::mechanism]` module (the text of its
    /// file, `include_str!`), for `show --code`.
    pub source: Option<&'static str>,
}

impl Entry {
    /// The entry of the model built by `make`, called `name`, with every other part at
    /// its default (not stiff, [`Scene::fallback`], no source).
    pub const fn new(
        name: &'static str,
        summary: &'static str,
        make: fn() -> Box<dyn Mechanism>,
    ) -> Self {
        Self {
            name,
            summary,
            make,
            stiff: false,
            scene: Scene::fallback(),
            source: None,
        }
    }

    /// Marks the model stiff (see [`Entry::stiff`](Self::stiff)).
    #[must_use]
    pub const fn stiff(mut self) -> Self {
        self.stiff = true;
        self
    }

    /// The one-line summary.
    #[must_use]
    pub const fn summary(mut self, summary: &'static str) -> Self {
        self.summary = summary;
        self
    }

    /// The default end time of `simulate` \[s\], and why that span.
    #[must_use]
    pub const fn span(mut self, t_end: f64, why: &'static str) -> Self {
        self.scene.t_end = t_end;
        self.scene.span = why;
        self
    }

    /// The default operating point of `linearize`.
    #[must_use]
    pub const fn steady(mut self, steady: Steady) -> Self {
        self.scene.steady = Some(steady);
        self
    }

    /// The exact solution from the default initial state, the reference of
    /// `work-precision`.
    #[must_use]
    pub const fn closed_form(mut self, exact: ClosedForm) -> Self {
        self.scene.closed_form = Some(exact);
        self
    }

    /// The exact impact times up to an end time (with a closed form).
    #[must_use]
    pub const fn impact_times(mut self, times: ImpactTimes) -> Self {
        self.scene.impact_times = Some(times);
        self
    }

    /// The source of the model's file, for `show --code`: `include_str!("my_model.rs")`.
    #[must_use]
    pub const fn source(mut self, source: &'static str) -> Self {
        self.source = Some(source);
        self
    }

    /// The summary, else the first line of the model's doc comment.
    pub fn description(&self, model: &dyn Mechanism) -> String {
        if self.summary.is_empty() {
            model
                .info()
                .doc
                .lines()
                .next()
                .unwrap_or("")
                .trim()
                .to_owned()
        } else {
            self.summary.to_owned()
        }
    }
}

/// The last segment of a path written as text (`a::b::name` gives `name`), for
/// [`model!`](crate::model).
#[doc(hidden)]
#[must_use]
pub const fn last_segment(path: &'static str) -> &'static str {
    let bytes = path.as_bytes();
    let mut start = bytes.len();
    while start > 0 && bytes[start - 1] != b':' && bytes[start - 1] != b' ' {
        start -= 1;
    }
    match core::str::from_utf8(bytes.split_at(start).1) {
        Ok(s) => s,
        Err(_) => path,
    }
}

/// The [`Entry`] of a `#[pfaff::mechanism]` module: named after the module (its last
/// path segment), built by `Box::new(path::Model::default())`, its summary the first
/// line of its doc comment unless given.
///
/// ```ignore
/// fn main() -> std::process::ExitCode {
///     pfaff_cli::main(&[
///         pfaff_cli::model!(double_pendulum)
///             .span(5.0, "a few swings")
///             .source(include_str!("main.rs")),
///         pfaff_cli::model!(my::pendulum, "a pendulum"),
///     ])
/// }
/// ```
#[macro_export]
macro_rules! model {
    ($($module:ident)::+) => {
        $crate::Entry::new(
            $crate::entry::last_segment(stringify!($($module)::+)),
            "",
            || ::std::boxed::Box::new(<$($module)::+::Model as ::core::default::Default>::default()),
        )
    };
    ($($module:ident)::+, $summary:expr) => {
        $crate::model!($($module)::+).summary($summary)
    };
}
