//! Every kind of error a user can make in a TOML file is located at the right line and column.
#![allow(clippy::unwrap_used, clippy::expect_used, missing_docs)]

use serde::{Deserialize, Serialize};
use toml_config::{TomlDoc, TomlError};

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct Point {
    x_m: f64,
    y_m: f64,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct Filter {
    r_sigma_px: f64,
    window: usize,
    points: Vec<Point>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct Doc {
    filter: Filter,
}

const GOOD: &str = "# comment\n[filter]\nr_sigma_px = 2.0\nwindow = 7\n\n[[filter.points]]\nx_m = 1.0\ny_m = 2.0\n\n[[filter.points]]\nx_m = 3.0\ny_m = 4.0\n";

fn located(e: &TomlError) -> (Option<usize>, Option<usize>) {
    (e.line, e.column)
}

#[test]
fn a_good_document_deserialises_whole_and_by_section() {
    let doc = TomlDoc::parse("good.toml", GOOD).unwrap();
    let d: Doc = doc.deserialize().unwrap();
    let f: Filter = doc.section("filter").unwrap();
    assert_eq!(d.filter, f);
    assert_eq!(f.points[1], Point { x_m: 3.0, y_m: 4.0 });
    assert_eq!(doc.keys().collect::<Vec<_>>(), vec!["filter"]);
}

#[test]
fn an_unknown_key_is_located_at_the_key_and_named() {
    let text = GOOD.replace("window = 7", "window = 7\nwindw = 8");
    let doc = TomlDoc::parse("c.toml", &text).unwrap();
    for e in [
        doc.section::<Filter>("filter").unwrap_err(),
        doc.deserialize::<Doc>().unwrap_err(),
    ] {
        assert_eq!(located(&e), (Some(5), Some(1)), "{e}");
        assert!(e.message.contains("unknown field `windw`"), "{e}");
        assert!(e.to_string().starts_with("c.toml:5:1: "), "{e}");
    }
}

#[test]
fn a_wrong_type_is_located_at_the_value_and_names_the_key() {
    let text = GOOD.replace("window = 7", "window = \"seven\"");
    let doc = TomlDoc::parse("c.toml", &text).unwrap();
    let e = doc.section::<Filter>("filter").unwrap_err();
    assert_eq!(located(&e), (Some(4), Some(10)), "{e}");
    assert!(e.message.contains("filter.window"), "{e}");
    let e = doc.deserialize::<Doc>().unwrap_err();
    assert_eq!(located(&e), (Some(4), Some(10)), "{e}");
    assert!(e.message.contains("filter.window"), "{e}");
}

#[test]
fn an_error_inside_an_array_of_tables_is_located_there() {
    let text = GOOD.replace("y_m = 4.0", "y_m = 4.0\nz_m = 5.0");
    let doc = TomlDoc::parse("c.toml", &text).unwrap();
    let e = doc.section::<Filter>("filter").unwrap_err();
    assert_eq!(located(&e), (Some(13), Some(1)), "{e}");
}

#[test]
fn a_missing_key_is_located_at_its_table() {
    let text = GOOD.replace("window = 7\n", "");
    let doc = TomlDoc::parse("c.toml", &text).unwrap();
    let e = doc.section::<Filter>("filter").unwrap_err();
    assert!(e.message.contains("missing field `window`"), "{e}");
    assert_eq!(e.line, Some(2), "{e}");
}

#[test]
fn a_syntax_error_is_located_at_the_bad_token() {
    let e = TomlDoc::parse("s.toml", "[filter]\nr_sigma_px = = 2\n").unwrap_err();
    assert_eq!(e.path, "s.toml");
    assert_eq!(e.line, Some(2), "{e}");
    assert!(e.to_string().starts_with("s.toml:2:"), "{e}");
    let e = TomlDoc::parse("s.toml", "[filter\n").unwrap_err();
    assert_eq!(e.line, Some(1), "{e}");
}

#[test]
fn a_missing_section_is_named_without_a_location() {
    let doc = TomlDoc::parse("m.toml", "[other]\na = 1\n").unwrap();
    let e = doc.section::<Filter>("filter").unwrap_err();
    assert_eq!(located(&e), (None, None));
    assert_eq!(e.to_string(), "m.toml: section [filter] missing");
}

#[test]
fn an_unknown_section_is_located_at_its_header() {
    let text = format!("{GOOD}\n[camera]\nfov_deg = 3.0\n");
    let doc = TomlDoc::parse("u.toml", &text).unwrap();
    let e = doc.allow_only(&["filter"]).unwrap_err();
    assert_eq!(located(&e), (Some(14), Some(2)), "{e}");
    assert!(e.message.contains("unknown section `camera`"), "{e}");
    doc.allow_only(&["filter", "camera"]).unwrap();
}

#[test]
fn error_at_finds_keys_array_elements_and_falls_back_to_the_parent() {
    let doc = TomlDoc::parse("v.toml", GOOD).unwrap();
    let e = doc.error_at("filter.r_sigma_px", "must be > 0");
    assert_eq!(e.to_string(), "v.toml:3:1: must be > 0");
    let e = doc.error_at("filter.points[1].y_m", "bad");
    assert_eq!(located(&e), (Some(12), Some(1)));
    // No such key: its table; no such element: the array.
    assert_eq!(located(&doc.error_at("filter.nope", "x")).0, Some(2));
    assert_eq!(
        located(&doc.error_at("filter.points[7].x_m", "x")).0,
        Some(6)
    );
    assert_eq!(located(&doc.error_at("nothing.here", "x")), (None, None));
}
