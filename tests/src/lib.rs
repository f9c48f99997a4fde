//! Integration, accuracy and snapshot tests of pfaff.
