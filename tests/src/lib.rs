//! Integration, accuracy and snapshot tests of pfaff.

#[cfg(test)]
mod accuracy;
