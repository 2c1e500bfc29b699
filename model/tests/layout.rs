//! The "where is each top" table in docs/architecture.md against the tree: every top with a
//! `.variants` file has exactly one row, and every path in the table exists.

use std::collections::BTreeSet;
use std::fs;
use std::path::Path;

/// Tops of every `rtl/**/<top>.variants`.
fn tops_with_variants(dir: &Path, out: &mut BTreeSet<String>) {
    for entry in fs::read_dir(dir).unwrap().flatten() {
        let path = entry.path();
        if path.is_dir() {
            tops_with_variants(&path, out);
        } else if path.extension().is_some_and(|e| e == "variants") {
            out.insert(path.file_stem().unwrap().to_string_lossy().into_owned());
        }
    }
}

/// Rows of the table under "## The tops, and where each one is": (top, cells).
fn table_rows(doc: &str) -> Vec<(String, Vec<String>)> {
    let section = doc
        .split("## The tops, and where each one is")
        .nth(1)
        .expect("docs/architecture.md has lost its section \"The tops, and where each one is\"");
    let section = section.split("\n## ").next().unwrap();
    section
        .lines()
        .filter(|l| l.starts_with("| `"))
        .map(|l| {
            let cells: Vec<String> = l
                .trim_matches('|')
                .split('|')
                .map(|c| c.trim().to_string())
                .collect();
            (cells[0].trim_matches('`').to_string(), cells)
        })
        .collect()
}

#[test]
fn every_top_has_one_row_and_every_path_in_it_exists() {
    let repo = cube5_model::repo_root();
    let doc = fs::read_to_string(repo.join("docs/architecture.md")).unwrap();
    let rows = table_rows(&doc);
    let mut tops = BTreeSet::new();
    tops_with_variants(&repo.join("rtl"), &mut tops);

    let listed: Vec<&str> = rows.iter().map(|(t, _)| t.as_str()).collect();
    for top in &tops {
        let n = listed.iter().filter(|t| *t == top).count();
        assert_eq!(n, 1, "top {top}: {n} rows in docs/architecture.md's table");
    }
    for (top, cells) in &rows {
        assert!(
            tops.contains(top),
            "docs/architecture.md lists {top}, which has no rtl/**/{top}.variants"
        );
        // Columns: top | what | RTL | model | contract | test | bench.
        assert_eq!(cells.len(), 7, "row of {top} has {} columns", cells.len());
        for path in &cells[2..] {
            assert!(
                repo.join(path).is_file(),
                "docs/architecture.md, row {top}: {path} does not exist"
            );
        }
        assert!(
            cells[2].ends_with(&format!("/{top}.sv")),
            "row {top}: the RTL column should be the top's own file, not {}",
            cells[2]
        );
        assert!(
            cells[5].ends_with(&format!("tests/{top}.rs")),
            "row {top}: the test column should be tb-rs/tests/{top}.rs (make sim TOP={top} runs it)"
        );
    }
}
