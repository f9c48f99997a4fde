//! Built-in pfaff mechanisms.
