//! Tests of the Monte Carlo driver, statistics and reports.
