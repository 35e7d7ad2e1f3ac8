//! The replay page in a real browser: the demo mission's `replay.html` is opened in headless
//! Chromium, played to its end under a virtual-time budget, and its state read from the DOM;
//! a screenshot is checked not to be blank; and the page is shown to make no request.
//!
//! Needs a headless Chromium (`chromium-headless-shell` from Debian, or `chromium`; or the path
//! in `PLUMETRACE_BROWSER`), so these tests are ignored by default; `.ci/run` installs the
//! browser and runs them with `--ignored`.

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// The browser to use.
fn browser() -> PathBuf {
    if let Some(p) = std::env::var_os("PLUMETRACE_BROWSER") {
        return PathBuf::from(p);
    }
    for name in ["chromium-headless-shell", "chromium", "chromium-browser"] {
        for dir in std::env::split_paths(&std::env::var_os("PATH").unwrap_or_default()) {
            let p = dir.join(name);
            if p.is_file() {
                return p;
            }
        }
    }
    panic!(
        "no headless Chromium found: install Debian's chromium-headless-shell or set PLUMETRACE_BROWSER"
    );
}

/// Runs the browser on `url` with `args`, killed after `limit`; returns its standard output.
fn run_browser(profile: &Path, args: &[String], url: &str, limit: Duration) -> String {
    let mut child = Command::new(browser())
        .args([
            "--no-sandbox",
            "--disable-gpu",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--hide-scrollbars",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .args(args)
        .arg(url)
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap_or_else(|e| panic!("starting the browser: {e}"));
    let mut out = child.stdout.take().unwrap();
    let reader = std::thread::spawn(move || {
        let mut s = String::new();
        let _ = std::io::Read::read_to_string(&mut out, &mut s);
        s
    });
    let started = Instant::now();
    loop {
        if child.try_wait().unwrap().is_some() {
            break;
        }
        if started.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            panic!("the browser did not finish within {limit:?}");
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    reader.join().unwrap()
}

/// The attributes of `<body ...>` in a dumped DOM.
fn body_attributes(dom: &str) -> std::collections::BTreeMap<String, String> {
    let start = dom
        .find("<body")
        .unwrap_or_else(|| panic!("no <body> in {dom:.300}"));
    let end = start + dom[start..].find('>').unwrap();
    let tag = &dom[start + 5..end];
    let mut out = std::collections::BTreeMap::new();
    let mut rest = tag;
    while let Some(eq) = rest.find("=\"") {
        let name = rest[..eq].trim().to_string();
        let after = &rest[eq + 2..];
        let close = after.find('"').unwrap();
        out.insert(name, after[..close].to_string());
        rest = &after[close + 1..];
    }
    out
}

fn file_url(p: &Path) -> String {
    format!("file://{}", p.canonicalize().unwrap().display())
}

/// The demo mission, flown once for all tests.
fn demo() -> &'static Path {
    static DIR: std::sync::OnceLock<tempfile::TempDir> = std::sync::OnceLock::new();
    DIR.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        common::run_ok(&[
            "run",
            "--preset",
            "demo",
            "--out",
            dir.path().to_str().unwrap(),
        ]);
        dir
    })
    .path()
}

#[test]
#[ignore = "needs a headless Chromium"]
fn the_demo_page_loads_its_data_and_plays_to_the_end() {
    let dir = demo();
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    let t_end = summary["ended"]["t_s"].as_f64().unwrap();
    // The last behaviour the planner switched to, from the event stream.
    let events = std::fs::read_to_string(dir.join("events.jsonl")).unwrap();
    let last_behaviour = events
        .lines()
        .rev()
        .filter_map(|l| serde_json::from_str::<serde_json::Value>(l).ok())
        .find(|e| e["event"] == "behaviour")
        .and_then(|e| e["behaviour"].as_str().map(str::to_string))
        .unwrap();
    let profile = tempfile::tempdir().unwrap();
    // At 200x the demo's mission (about 1,200 s) is 6 s of page time: well inside the budget.
    let dom = run_browser(
        profile.path(),
        &["--virtual-time-budget=60000".into(), "--dump-dom".into()],
        &format!("{}#speed=200", file_url(&dir.join("replay.html"))),
        Duration::from_secs(120),
    );
    let a = body_attributes(&dom);
    assert_eq!(a.get("data-loaded").map(String::as_str), Some("1"), "{a:?}");
    assert_eq!(a.get("data-ended").map(String::as_str), Some("1"), "{a:?}");
    assert_eq!(
        a.get("data-vehicles").map(String::as_str),
        Some("1"),
        "{a:?}"
    );
    assert_eq!(
        a.get("data-blocked").map(String::as_str),
        Some("0"),
        "{a:?}"
    );
    let t: f64 = a["data-t"].parse().unwrap();
    let t_page_end: f64 = a["data-t-end"].parse().unwrap();
    assert!(
        (t - t_end).abs() < 0.11,
        "page at {t} s, mission ended at {t_end} s"
    );
    assert!((t_page_end - t_end).abs() < 0.11);
    let frames: u64 = a["data-frames"].parse().unwrap();
    // The page draws 25 frames a second of page time; allow a fifth fewer for start-up.
    let expected = t_end / 200.0 * 25.0;
    assert!(
        frames as f64 > 0.8 * expected,
        "only {frames} frames drawn, {expected:.0} expected"
    );
    assert_eq!(a["data-behaviour"], last_behaviour);
}

#[test]
#[ignore = "needs a headless Chromium"]
fn a_screenshot_of_the_demo_page_is_not_blank() {
    let dir = demo();
    let profile = tempfile::tempdir().unwrap();
    let shot = profile.path().join("shot.png");
    run_browser(
        profile.path(),
        &[
            "--virtual-time-budget=3000".into(),
            "--window-size=1200,900".into(),
            format!("--screenshot={}", shot.display()),
        ],
        &format!("{}#t=900&paused", file_url(&dir.join("replay.html"))),
        Duration::from_secs(120),
    );
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&shot).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    let channels = info.color_type.samples();
    let pixels: Vec<&[u8]> = buf[..info.buffer_size()].chunks(channels).collect();
    assert!(pixels.len() >= 1200 * 900, "{} pixels", pixels.len());
    // Not blank: many colours, and a good share of the pixels unlike the page's background.
    let background = pixels[pixels.len() - 1];
    let differing = pixels.iter().filter(|p| **p != background).count();
    let colours: std::collections::BTreeSet<&[u8]> = pixels.iter().copied().collect();
    assert!(
        differing * 10 > pixels.len(),
        "only {differing} of {} pixels differ from the background",
        pixels.len()
    );
    assert!(colours.len() > 200, "only {} colours", colours.len());
    // The plume (reds) and the tracks are there: count strongly red pixels.
    let red = pixels
        .iter()
        .filter(|p| p[0] > 180 && p[1] < 120 && p[2] < 120)
        .count();
    assert!(red > 200, "only {red} red pixels");
}

#[test]
#[ignore = "needs a headless Chromium"]
fn the_page_makes_no_request_and_would_report_one() {
    let dir = demo();
    let html = std::fs::read_to_string(dir.join("replay.html")).unwrap();
    // Statically: nothing that loads from elsewhere.
    for needle in [
        "src=",
        "href=",
        "<link",
        "@import",
        "url(",
        "fetch(",
        "XMLHttpRequest",
        "WebSocket",
        "EventSource",
        "sendBeacon",
        "import(",
        "http://",
        "https://",
    ] {
        assert!(!html.contains(needle), "the page contains {needle:?}");
    }
    assert!(html.contains("Content-Security-Policy\" content=\"default-src 'none'"));
    let size = html.len();
    assert!(size < 5_000_000, "the demo page is {size} bytes");
    // Dynamically: the page counts requests its security policy refuses. A copy with an image
    // from elsewhere must count one (so a page that counts zero made none).
    let bad = html.replacen(
        "<div id=\"strips\">",
        "<img alt=\"\" src=\"http://192.0.2.1/x.png\"><div id=\"strips\">",
        1,
    );
    let copy = tempfile::tempdir().unwrap();
    std::fs::write(copy.path().join("bad.html"), bad).unwrap();
    let profile = tempfile::tempdir().unwrap();
    let dom = run_browser(
        profile.path(),
        &["--virtual-time-budget=3000".into(), "--dump-dom".into()],
        &format!("{}#paused", file_url(&copy.path().join("bad.html"))),
        Duration::from_secs(120),
    );
    let a = body_attributes(&dom);
    assert_eq!(a.get("data-loaded").map(String::as_str), Some("1"), "{a:?}");
    let blocked: u32 = a["data-blocked"].parse().unwrap();
    assert!(blocked >= 1, "the refused image was not counted: {a:?}");
}
