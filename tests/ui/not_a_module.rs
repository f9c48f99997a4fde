#[pfaff::mechanism]
fn pendulum() {}
fn main() {}
