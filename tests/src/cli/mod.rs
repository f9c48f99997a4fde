//! Tests of what the `pfaff` command-line program relies on in the library: the
//! linearization of the reduced system (`pfaff linearize`). The program itself is
//! tested by running its binary, in `models/tests/cli_*.rs`.

mod linearize;
