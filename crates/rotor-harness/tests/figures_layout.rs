//! Every committed figure, rendered by a real browser: no text reaches outside its figure and
//! no two texts overlap (legend entries, tick labels, axis labels, point and curve names).
//!
//! Headless Chromium lays out a page that holds every SVG of `reports/` and `reports/bench/`
//! inline, and `layout/check.js` measures each text's box after layout (the browser's own
//! font metrics, not the writer's estimate). The test skips without Chromium, unless
//! `ROTOR_REQUIRE_BROWSER=1` (CI installs Debian's chromium and sets it), which makes a
//! missing browser a failure.

use std::path::{Path, PathBuf};
use std::process::Command;

const CHECK_JS: &str = include_str!("layout/check.js");

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn browser() -> Option<&'static str> {
    let found = ["chromium", "chromium-browser", "google-chrome"]
        .into_iter()
        .find(|b| {
            Command::new(b)
                .arg("--version")
                .output()
                .is_ok_and(|o| o.status.success())
        });
    if found.is_none() && std::env::var_os("ROTOR_REQUIRE_BROWSER").is_some_and(|v| v == "1") {
        panic!("ROTOR_REQUIRE_BROWSER=1 but no chromium on PATH");
    }
    found
}

/// One figure's measured layout.
#[derive(serde::Deserialize, Debug)]
struct Layout {
    name: String,
    texts: usize,
    outside: Vec<String>,
    overlaps: Vec<[String; 2]>,
}

/// Renders `figures` (name, SVG text) inline in one page and returns what check.js measured.
fn measure(browser: &str, figures: &[(String, String)]) -> Vec<Layout> {
    let dir = rotor_testkit::tmp_dir("rotor-layout");
    let mut page =
        String::from("<!DOCTYPE html><html><head><meta charset=\"utf-8\"></head><body>\n");
    for (name, svg) in figures {
        page.push_str(&svg.replacen("<svg ", &format!("<svg data-name=\"{name}\" "), 1));
    }
    page.push_str("<script>");
    page.push_str(CHECK_JS);
    page.push_str("</script></body></html>\n");
    let html = dir.join("page.html");
    std::fs::write(&html, page).unwrap();
    let out = Command::new(browser)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--virtual-time-budget=20000",
        ])
        .arg(format!("--user-data-dir={}", dir.join("profile").display()))
        .arg("--dump-dom")
        .arg(format!("file://{}", html.display()))
        .output()
        .expect("chromium runs");
    let dom = String::from_utf8_lossy(&out.stdout);
    let start = dom.rfind("<pre id=\"layout\">").unwrap_or_else(|| {
        panic!(
            "no layout in the page: {}",
            String::from_utf8_lossy(&out.stderr)
        )
    });
    let json = &dom[start + "<pre id=\"layout\">".len()..];
    let json = &json[..json.find("</pre>").unwrap()];
    let json = json
        .replace("&quot;", "\"")
        .replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&amp;", "&");
    std::fs::remove_dir_all(&dir).ok();
    serde_json::from_str(&json).unwrap_or_else(|e| panic!("{e}: {json}"))
}

fn committed_figures() -> Vec<(String, String)> {
    let mut v = Vec::new();
    for sub in ["reports", "reports/bench"] {
        let dir = repo().join(sub);
        let mut names: Vec<PathBuf> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|x| x == "svg"))
            .collect();
        names.sort();
        for p in names {
            let name = format!("{sub}/{}", p.file_name().unwrap().to_string_lossy());
            v.push((name, std::fs::read_to_string(&p).unwrap()));
        }
    }
    v
}

#[test]
fn no_committed_figure_has_text_outside_it_or_text_over_text() {
    let Some(b) = browser() else {
        eprintln!("skipped: no chromium on PATH (CI sets ROTOR_REQUIRE_BROWSER=1)");
        return;
    };
    let figures = committed_figures();
    assert!(figures.len() >= 40, "{} figures", figures.len());
    let layout = measure(b, &figures);
    assert_eq!(layout.len(), figures.len());
    let bad: Vec<String> = layout
        .iter()
        .filter(|l| !l.outside.is_empty() || !l.overlaps.is_empty())
        .map(|l| {
            format!(
                "{}: outside {:?}, overlapping {:?}",
                l.name, l.outside, l.overlaps
            )
        })
        .collect();
    assert!(bad.is_empty(), "{}", bad.join("\n"));
    // Every figure has its texts measured (a title, ticks, axis labels at least).
    assert!(layout.iter().all(|l| l.texts >= 5), "{layout:?}");
}

/// The check sees what it is for: a legend entry past the right edge, a label over a tick
/// label, and a text turned upright across another; a clean figure passes.
#[test]
fn the_layout_check_finds_text_outside_and_text_over_text() {
    let Some(b) = browser() else {
        eprintln!("skipped: no chromium on PATH");
        return;
    };
    let svg = |body: &str| {
        format!(
            r#"<svg xmlns="http://www.w3.org/2000/svg" width="300" height="200" viewBox="0 0 300 200" font-family="sans-serif" font-size="12">{body}</svg>"#
        )
    };
    let figures = vec![
        (
            "clean".to_string(),
            svg(r#"<text x="10" y="20">title</text><text x="10" y="60">a tick</text>"#),
        ),
        (
            "outside".to_string(),
            svg(
                r#"<text x="10" y="20">title</text><text x="260" y="60">a long legend entry</text>"#,
            ),
        ),
        (
            "overlap".to_string(),
            svg(r#"<text x="10" y="20">title</text><text x="14" y="22">label</text>"#),
        ),
        (
            "turned".to_string(),
            svg(
                r#"<text x="50" y="100" transform="rotate(-90 50 100)">a y label</text><text x="40" y="100">4.2799</text>"#,
            ),
        ),
    ];
    let layout = measure(b, &figures);
    let by = |n: &str| layout.iter().find(|l| l.name == n).unwrap();
    assert!(by("clean").outside.is_empty() && by("clean").overlaps.is_empty());
    assert_eq!(by("outside").outside, ["a long legend entry"]);
    assert_eq!(by("overlap").overlaps.len(), 1);
    assert_eq!(by("turned").overlaps.len(), 1);
}
