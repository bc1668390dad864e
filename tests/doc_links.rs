//! The repository's Markdown documents link to each other's sections: every relative link
//! `path.md#anchor` (or `#anchor` within a document) must name a heading of its target, with
//! the anchor GitHub gives it (lower case; letters, digits, spaces, `-` and `_` kept, spaces
//! made `-`, every other character dropped, so "1.6 Nonlinear Gauss–Seidel" becomes
//! `16-nonlinear-gaussseidel`; a repeated heading gets `-1`, `-2`, …), and every relative link
//! must name a file that exists. A renamed heading or a moved file then fails here rather than
//! leaving a reader on the top of a page.

use std::collections::HashSet;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// GitHub's anchor of a heading's text.
fn slug(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter(|c| c.is_alphanumeric() || matches!(c, ' ' | '-' | '_'))
        .map(|c| if c == ' ' { '-' } else { c })
        .collect()
}

/// The heading's text as rendered: code spans, emphasis and links reduced to their text.
fn rendered(text: &str) -> String {
    let mut out = String::new();
    let mut rest = text;
    while let Some(i) = rest.find('[') {
        out.push_str(&rest[..i]);
        let tail = &rest[i + 1..];
        match (tail.find("]("), tail.find(')')) {
            (Some(j), Some(k)) if j < k => {
                out.push_str(&tail[..j]);
                rest = &tail[k + 1..];
            }
            _ => {
                out.push('[');
                rest = tail;
            }
        }
    }
    out.push_str(rest);
    out.replace(['`', '*'], "")
}

/// The anchors of a Markdown file's headings (outside fenced code).
fn anchors(path: &Path) -> HashSet<String> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut seen: std::collections::HashMap<String, usize> = Default::default();
    let mut out = HashSet::new();
    let mut fenced = false;
    for line in text.lines() {
        if line.starts_with("```") {
            fenced = !fenced;
        }
        if fenced {
            continue;
        }
        let hashes = line.chars().take_while(|&c| c == '#').count();
        if !(1..=6).contains(&hashes) || !line[hashes..].starts_with(' ') {
            continue;
        }
        let s = slug(&rendered(line[hashes..].trim_end_matches('#')));
        let n = seen.entry(s.clone()).or_insert(0);
        out.insert(if *n == 0 {
            s.clone()
        } else {
            format!("{s}-{n}")
        });
        *n += 1;
    }
    out
}

/// The Markdown files of the repository, outside build output and dependencies.
fn documents() -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![root()];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            let name = path.file_name().unwrap().to_string_lossy().to_string();
            if path.is_dir() {
                if !name.starts_with('.') && !["target", "node_modules"].contains(&name.as_str()) {
                    stack.push(path);
                }
            } else if name.ends_with(".md") {
                out.push(path);
            }
        }
    }
    out.sort();
    out
}

/// `(line, target)` of every inline link `](target)` of a document, outside fenced code.
fn links(text: &str) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    let mut fenced = false;
    for (n, line) in text.lines().enumerate() {
        if line.starts_with("```") {
            fenced = !fenced;
        }
        if fenced {
            continue;
        }
        let mut rest = line;
        while let Some(i) = rest.find("](") {
            let tail = &rest[i + 2..];
            let Some(end) = tail.find(')') else { break };
            out.push((n + 1, tail[..end].to_string()));
            rest = &tail[end..];
        }
    }
    out
}

#[test]
fn relative_links_and_their_anchors_resolve() {
    let docs = documents();
    assert!(
        docs.iter().any(|d| d.ends_with("docs/physics.md")),
        "the documents were not found under {}",
        root().display()
    );
    let mut broken = Vec::new();
    let mut checked = 0;
    for doc in &docs {
        let text = std::fs::read_to_string(doc).unwrap();
        for (line, target) in links(&text) {
            if target.contains("://") || target.starts_with("mailto:") || target.contains(' ') {
                continue;
            }
            let (file, anchor) = match target.split_once('#') {
                Some((f, a)) => (f, Some(a)),
                None => (target.as_str(), None),
            };
            // A path has a directory or an extension (`proj_[a, b](z_t)` in a formula is no
            // link).
            if !file.is_empty() && !file.contains('/') && !file.contains('.') {
                continue;
            }
            let path = if file.is_empty() {
                doc.clone()
            } else {
                doc.parent().unwrap().join(file)
            };
            let place = format!(
                "{}:{line}: {target}",
                doc.strip_prefix(root()).unwrap().display()
            );
            if !path.exists() {
                broken.push(format!("{place} (no such file)"));
                continue;
            }
            checked += 1;
            if let Some(a) = anchor.filter(|_| path.extension().is_some_and(|e| e == "md")) {
                if !anchors(&path).contains(a) {
                    broken.push(format!("{place} (no such heading)"));
                }
            }
        }
    }
    assert!(checked >= 20, "only {checked} relative links found");
    assert!(broken.is_empty(), "broken links:\n{}", broken.join("\n"));
}

#[test]
fn anchors_follow_github() {
    assert_eq!(
        slug(&rendered("1.6 Nonlinear Gauss–Seidel over contacts")),
        "16-nonlinear-gaussseidel-over-contacts"
    );
    assert_eq!(
        slug(&rendered("3.6 `shear-cell` [outputs](x.md)")),
        "36-shear-cell-outputs"
    );
    assert_eq!(slug("μ(I) and φ(I)"), "μi-and-φi");
}

/// The README is a front page: under 200 lines; its first code block, before any section, is
/// the two commands a newcomer types on a fresh machine, the main job and all the tests; it
/// names its prerequisites; and it links every page of `docs/` (whose links the test above
/// resolves), so that what was moved there from the README stays reachable.
#[test]
fn the_readme_is_a_front_page() {
    let text = std::fs::read_to_string(root().join("README.md")).unwrap();
    let n = text.lines().count();
    assert!(n < 200, "README.md has {n} lines");
    let first_section = text.find("\n## ").expect("a section");
    let start = text.find("```sh\n").expect("a shell block") + 6;
    assert!(
        start < first_section,
        "the commands come before any section"
    );
    let end = start + text[start..].find("```").unwrap();
    let commands: Vec<&str> = text[start..end]
        .lines()
        .map(|l| l.split('#').next().unwrap().trim())
        .collect();
    assert_eq!(commands, ["cargo run --release", "scripts/test-all.sh"]);
    assert!(text.contains("\n## Prerequisites\n"));
    for page in std::fs::read_dir(root().join("docs")).unwrap() {
        let name = page.unwrap().file_name().to_string_lossy().to_string();
        if name.ends_with(".md") {
            assert!(
                text.contains(&format!("](docs/{name}")),
                "README.md does not link docs/{name}"
            );
        }
    }
}
