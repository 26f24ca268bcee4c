//! `report.html` in a real browser: a small report with two figures and a table is written,
//! and every bundled example's report as its command writes it;
//! then opened in headless Chromium, which must load it with no script error and lay out every
//! figure with a non-zero size. Chromium comes from Debian's `chromium` package (`.ci/run`
//! installs it and sets `STF_LAB_REQUIRE_BROWSER=1`, so there a missing browser fails the
//! test); elsewhere, with no browser on PATH, the browser check is skipped and says so, so
//! the README's test command passes on a fresh machine.
//!
//! Set `STF_REPORT_TEST_OUT=DIR` to keep the report, its figures and the browser's screenshot
//! in DIR for a look.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

mod common;

use stf_lab::report;
use stf_lab::report::test_signals::damped_sine;
use stf_lab::report::{FigureRef, Motion, Report, Section, Table};

fn find_chromium() -> Option<PathBuf> {
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .flat_map(|dir| ["chromium", "chromium-browser"].map(|name| dir.join(name)))
        .find(|p| p.is_file())
}

/// Chromium, or `None` (the browser check skipped, and said on stderr) when there is none on
/// PATH — a failure instead when `STF_LAB_REQUIRE_BROWSER=1` (CI).
fn browser_or_skip() -> Option<PathBuf> {
    let found = find_chromium();
    if found.is_none() {
        let how = "install Debian's package (apt-get install -y chromium), as .ci/run does";
        if std::env::var("STF_LAB_REQUIRE_BROWSER").as_deref() == Ok("1") {
            panic!("chromium not found on PATH and STF_LAB_REQUIRE_BROWSER=1: {how}");
        }
        // Straight to stderr, past the test harness's capture, so `cargo test` shows it.
        let _ = writeln!(
            std::io::stderr(),
            "chromium not found on PATH: the report's browser check is SKIPPED ({how}; \
             STF_LAB_REQUIRE_BROWSER=1 makes a missing browser a failure)"
        );
    }
    found
}

/// Run Chromium headless on `page` with the extra `args`; returns stdout. Output goes to files
/// (a large DOM would fill a pipe nobody reads yet). A safety limit of two minutes ends a
/// browser that hangs (the test then fails).
fn run_chromium(chromium: &Path, page: &Path, args: &[String]) -> String {
    let profile = tempfile::tempdir().unwrap();
    let stdout_path = profile.path().join("stdout.txt");
    let stderr_path = profile.path().join("stderr.txt");
    let mut child = Command::new(chromium)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--hide-scrollbars",
            "--window-size=1200,2000",
            "--virtual-time-budget=10000",
        ])
        .arg(format!(
            "--user-data-dir={}",
            profile.path().join("profile").display()
        ))
        .args(args)
        .arg(format!("file://{}", page.display()))
        .stdin(Stdio::null())
        .stdout(std::fs::File::create(&stdout_path).unwrap())
        .stderr(std::fs::File::create(&stderr_path).unwrap())
        .spawn()
        .expect("cannot start chromium");
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if start.elapsed() > Duration::from_secs(120) {
            let _ = child.kill();
            let _ = child.wait();
            panic!("chromium did not finish within 2 minutes");
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    assert!(
        status.success(),
        "chromium failed ({status}): {}",
        std::fs::read_to_string(&stderr_path).unwrap_or_default()
    );
    std::fs::read_to_string(&stdout_path).unwrap()
}

/// The page's own layout check (written by its script into `#layout-check`): no script
/// error, `figures` figures, each laid out with a non-zero size.
fn check_layout(dom: &str, figures: usize) {
    let check = dom
        .split("<pre id=\"layout-check\" hidden=\"\">")
        .nth(1)
        .and_then(|rest| rest.split("</pre>").next())
        .unwrap_or_else(|| panic!("no layout-check in the DOM:\n{dom}"));
    assert!(!check.contains("error:"), "page errors:\n{check}");
    assert!(
        check.contains(&format!("figures {figures}")),
        "layout check:\n{check}"
    );
    let lines: Vec<&str> = check.lines().filter(|l| l.starts_with("figure ")).collect();
    assert_eq!(lines.len(), figures, "{check}");
    for line in lines {
        // "figure 0 img 1000x1000 natural 1000x1000"
        let sizes: Vec<(u32, u32)> = line
            .split_whitespace()
            .filter(|w| w.contains('x') && w.chars().next().is_some_and(|c| c.is_ascii_digit()))
            .map(|w| {
                let (a, b) = w.split_once('x').unwrap();
                (a.parse().unwrap(), b.parse().unwrap())
            })
            .collect();
        assert_eq!(sizes.len(), 2, "{line}");
        for (w, h) in sizes {
            assert!(w > 0 && h > 0, "a figure has zero size: {line}");
        }
    }
}

fn build_report(dir: &Path) -> PathBuf {
    let s = damped_sine(5_000, 5.0);
    let motion = Motion {
        t: &s.t,
        x: &s.x,
        v: &s.v,
        a: &s.a,
    };
    let figures = dir.join("figures");
    let history = report::time_history(
        &figures,
        "time_history",
        &motion,
        Some(&s.f),
        &report::MotionLabels::LENGTH,
    )
    .unwrap();
    let loop_v = report::hysteresis(
        &figures,
        "hysteresis_v",
        ("velocity v, m/s", &s.v),
        ("F_STF, N", &s.f),
        &s.t,
    )
    .unwrap();

    let mut r = Report::new("Power-law fit of a synthetic record");
    r.intro.push(
        "A damped oscillation of the trolley (5 mm, 2 Hz) with an STF force that grows with \
         the square of the velocity. This page is self-contained: it needs no network."
            .into(),
    );
    let mut fit = Section::new("Fitted parameters");
    fit.paragraphs
        .push("Values with their standard errors, from the fitted force.".into());
    fit.tables.push(Table {
        caption: "Power law F = K·|v|^n·sign(v)".into(),
        columns: vec!["parameter".into(), "value".into(), "unit".into()],
        rows: vec![
            vec!["K".into(), "402.1 ± 3.5".into(), "N (s/m)^n".into()],
            vec!["n".into(), "1.98 ± 0.02".into(), "".into()],
        ],
    });
    r.sections.push(fit);
    let mut figs = Section::new("Figures");
    figs.figures.push(
        FigureRef::new(
            history,
            "Displacement, velocity, acceleration and the STF force over time, a panel each; \
             black dots mark the force's maxima, circles its minima.",
        )
        .zoomable(),
    );
    figs.figures.push(FigureRef::new(
        loop_v,
        "The STF force against velocity; the colour shows time, from dark (start) to yellow \
         (end).",
    ));
    r.sections.push(figs);

    let page = dir.join("report.html");
    report::write_html(&r, &page).unwrap();
    report::write_markdown(&r, &dir.join("report.md")).unwrap();
    page
}

#[test]
fn report_html_renders_every_figure_in_headless_chromium() {
    let kept = std::env::var_os("STF_REPORT_TEST_OUT").map(PathBuf::from);
    let tmp = tempfile::tempdir().unwrap();
    let dir = kept.clone().unwrap_or_else(|| tmp.path().to_path_buf());
    std::fs::create_dir_all(&dir).unwrap();
    let dir = dir.canonicalize().unwrap();
    let page = build_report(&dir);

    let html = std::fs::read_to_string(&page).unwrap();
    assert_eq!(html.matches("<svg class=\"figure").count(), 2);
    assert_eq!(html.matches("<svg class=\"figure zoom\"").count(), 1);
    assert!(!html.contains("<img"), "figures are inline SVG");
    assert!(!html.contains("http://") && !html.contains("https://"));
    let md = std::fs::read_to_string(dir.join("report.md")).unwrap();
    assert!(md.contains("](figures/time_history.png)"), "{md}");

    let Some(chromium) = browser_or_skip() else {
        return;
    };

    let dom = run_chromium(&chromium, &page, &["--dump-dom".to_string()]);
    check_layout(&dom, 2);

    let shot = dir.join("screenshot.png");
    run_chromium(
        &chromium,
        &page,
        &[format!("--screenshot={}", shot.display())],
    );
    let png = std::fs::read(&shot).unwrap();
    assert!(png.len() > 10_000, "screenshot is {} bytes", png.len());
}

/// What the test page's injected script saw of the first zoomable figure's `viewBox`, one
/// line per step: `initial`, after a wheel event zooming in at its middle, after a drag to the
/// right, after a double-click.
const ZOOM_PROBE: &str = r#"<script>
window.addEventListener("load", function () {
  var svg = document.querySelector("svg.zoom");
  var r = svg.getBoundingClientRect();
  var lines = ["initial " + svg.getAttribute("viewBox")];
  var at = { clientX: r.left + r.width / 2, clientY: r.top + r.height / 2, bubbles: true,
             cancelable: true };
  svg.dispatchEvent(new WheelEvent("wheel", Object.assign({ deltaY: -500 }, at)));
  lines.push("wheel " + svg.getAttribute("viewBox"));
  svg.dispatchEvent(new PointerEvent("pointerdown", Object.assign({ pointerId: 1 }, at)));
  at.clientX += 100;
  svg.dispatchEvent(new PointerEvent("pointermove", Object.assign({ pointerId: 1 }, at)));
  svg.dispatchEvent(new PointerEvent("pointerup", Object.assign({ pointerId: 1 }, at)));
  lines.push("drag " + svg.getAttribute("viewBox"));
  svg.dispatchEvent(new MouseEvent("dblclick", at));
  lines.push("reset " + svg.getAttribute("viewBox"));
  var pre = document.createElement("pre");
  pre.id = "zoom-probe";
  pre.textContent = lines.join("\n");
  document.body.appendChild(pre);
});
</script>"#;

/// A `viewBox`'s four numbers from the probe's line `step …`.
fn view_box(probe: &str, step: &str) -> [f64; 4] {
    let line = probe
        .lines()
        .find(|l| l.starts_with(step))
        .unwrap_or_else(|| panic!("no `{step}` in the zoom probe:\n{probe}"));
    let v: Vec<f64> = line[step.len()..]
        .split_whitespace()
        .map(|w| w.parse().unwrap())
        .collect();
    v.try_into().unwrap()
}

/// The time history's wheel zooms its time axis (x and width of the `viewBox` only), a drag
/// pans it to earlier times, a double-click resets it: a copy of the page with a probe script
/// injected, run in headless Chromium.
#[test]
fn a_time_history_zooms_pans_and_resets_in_headless_chromium() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().canonicalize().unwrap();
    let page = build_report(&dir);
    let Some(chromium) = browser_or_skip() else {
        return;
    };
    let html = std::fs::read_to_string(&page).unwrap();
    let probed = dir.join("probed.html");
    std::fs::write(
        &probed,
        html.replace("</body>", &format!("{ZOOM_PROBE}</body>")),
    )
    .unwrap();
    let dom = run_chromium(&chromium, &probed, &["--dump-dom".to_string()]);
    let probe = dom
        .split("<pre id=\"zoom-probe\">")
        .nth(1)
        .and_then(|rest| rest.split("</pre>").next())
        .unwrap_or_else(|| panic!("no zoom probe in the DOM (a script error?)"));
    let initial = view_box(probe, "initial ");
    let wheel = view_box(probe, "wheel ");
    let drag = view_box(probe, "drag ");
    let reset = view_box(probe, "reset ");
    assert!(wheel[2] < 0.5 * initial[2], "zoomed in: {probe}");
    assert_eq!(
        (wheel[1], wheel[3]),
        (initial[1], initial[3]),
        "time axis only: {probe}"
    );
    let middle = initial[0] + initial[2] / 2.0;
    assert!(
        (wheel[0] + wheel[2] / 2.0 - middle).abs() < 1.0,
        "about the pointer: {probe}"
    );
    assert!(
        drag[0] < wheel[0] && (drag[2] - wheel[2]).abs() < 1e-3,
        "dragged right, earlier times: {probe}"
    );
    assert_eq!(reset, initial, "{probe}");
}

/// Every bundled example's report, as its command writes it, loads in the browser with every
/// figure laid out; with `STF_REPORT_TEST_OUT=DIR` each page's screenshot is kept in DIR.
#[test]
fn every_bundled_report_lays_out_every_figure_in_headless_chromium() {
    let kept = std::env::var_os("STF_REPORT_TEST_OUT").map(PathBuf::from);
    let Some(chromium) = browser_or_skip() else {
        return;
    };
    let tmp = tempfile::tempdir().unwrap();
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    for (command, example) in [
        ("fit", "power_law_fit"),
        ("fit", "paper_identification"),
        ("compare", "jamming_compare"),
        ("discover", "discovery"),
        ("discover", "trajectory_discovery"),
    ] {
        let out = tmp.path().join(example);
        let experiment = root.join("experiments").join(format!("{example}.toml"));
        common::run_ok(command, &experiment, &out);
        let page = out.join("report.html").canonicalize().unwrap();
        let html = std::fs::read_to_string(&page).unwrap();
        let figures = html.matches("<svg class=\"figure").count();
        assert!(
            html.contains("<svg class=\"figure zoom\""),
            "{example}: no zoomable figure"
        );
        assert!(figures >= 2, "{example}: {figures} figures");
        let dom = run_chromium(&chromium, &page, &["--dump-dom".to_string()]);
        check_layout(&dom, figures);
        if let Some(dir) = &kept {
            std::fs::create_dir_all(dir).unwrap();
            let shot = dir.join(format!("{example}.png"));
            run_chromium(
                &chromium,
                &page,
                &[format!("--screenshot={}", shot.display())],
            );
        }
    }
}
