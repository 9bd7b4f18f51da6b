//! `reports/index.html`: the whole report on one page, readable offline in a browser.
//!
//! It is the report's `README.md` rendered to HTML (CommonMark with tables), so the two never
//! say different things: the agreement and gate tables, the friction curves, the bifurcation
//! diagrams, Figure 3 by three methods, the planes and the stress table, each figure shown
//! where the text links it. After it, every scenario's figure, and the benchmark's summary
//! with a link to its page of per-scene figures (`bench/bench.html`), when they exist.

use pulldown_cmark::{Options, Parser, html};

/// The page for the report whose markdown is `md`, with the scenarios' figures named
/// `<name>.svg` beside it; `bench` says whether `bench/bench.svg` and `bench/bench.html` are
/// there.
pub(crate) fn index_html(md: &str, scenarios: &[&str], bench: bool) -> String {
    let mut body = String::new();
    html::push_html(&mut body, Parser::new_ext(md, Options::ENABLE_TABLES));
    let mut page = String::from(
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\
         <title>rotorbench report</title>\n<style>\
         body{font-family:sans-serif;max-width:960px;margin:2em auto;padding:0 1em}\
         img{max-width:100%}table{border-collapse:collapse;font-size:90%}\
         td,th{border:1px solid #ccc;padding:2px 6px}\
         figure{margin:2em 0}</style></head><body>\n",
    );
    page.push_str(&body);
    page.push_str("<h2>Every scenario's figure</h2>\n");
    for name in scenarios {
        let name = esc(name);
        page.push_str(&format!(
            "<figure id=\"{name}\"><img src=\"{name}.svg\" alt=\"{name}: the three solvers and \
             their differences\"><figcaption>{name} (<a href=\"{name}.svg\">SVG</a>, \
             <a href=\"{name}.csv\">CSV</a>)</figcaption></figure>\n"
        ));
    }
    if bench {
        page.push_str(
            "<h2>Work precision</h2>\n<figure><img src=\"bench/bench.svg\" alt=\"performance \
             profiles\"><figcaption>The performance profiles of the last benchmark run; every \
             scene's work-precision figure is on <a href=\"bench/bench.html\">its own page</a>.\
             </figcaption></figure>\n",
        );
    }
    page.push_str("</body></html>\n");
    page
}

fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_markdown_tables_and_images_become_html() {
        let md = "# r\n\n![friction](friction.svg)\n\n| a | b |\n|---|---|\n| 1 | 2 |\n";
        let page = index_html(md, &["t1-u1.5-rest"], true);
        assert!(page.starts_with("<!DOCTYPE html>") && page.ends_with("</html>\n"));
        assert!(page.contains(r#"<img src="friction.svg" alt="friction""#));
        assert!(page.contains("<table>") && page.contains("<td>2</td>"));
        assert!(page.contains(r#"<img src="t1-u1.5-rest.svg""#));
        assert!(page.contains(r#"href="bench/bench.html""#));
        assert!(!index_html(md, &[], false).contains("bench/bench.svg"));
    }
}
