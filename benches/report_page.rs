//! How long the HTML report page takes to render in a headless browser: a synthetic campaign of
//! 200 plants × 5 orders (1 000 entries, 2 figures each), timed by the page itself (its
//! `data-render-ms`, from the first script line to the filled table) over `--reps` browser runs.
//! Target: the median under 2 000 ms. Not a test (browser start and page render depend on the
//! machine's load); `tests/html_report.rs` checks that the page shows every row.
//!
//! ```text
//! cargo bench --bench report_page -- [--plants 200] [--orders 5] [--reps 5]
//! ```
//!
//! `HINFIX_BROWSER` names the browser's executable (default: chromium and its usual names).

#[path = "../tests/common/browser.rs"]
mod browser;

fn arg(name: &str, default: usize) -> usize {
    let args: Vec<String> = std::env::args().collect();
    match args.iter().position(|a| a == name) {
        None => default,
        Some(i) => args
            .get(i + 1)
            .and_then(|v| v.parse().ok())
            .unwrap_or_else(|| panic!("{name} needs a positive whole number")),
    }
}

fn main() {
    let (plants, orders, reps) = (arg("--plants", 200), arg("--orders", 5), arg("--reps", 5).max(1));
    let Some(b) = browser::browser() else { return };
    let dir = tempfile::tempdir().unwrap();
    let (best, page) = browser::synthetic(dir.path(), plants, orders);
    let mut ms = Vec::with_capacity(reps);
    for rep in 1..=reps {
        let started = std::time::Instant::now();
        let dom = browser::dump_dom(&b, &page, false);
        let wall = started.elapsed().as_secs_f64();
        assert_eq!(dom.matches("<tr><td>").count(), best.len(), "rows shown");
        let t = browser::render_ms(&dom);
        println!("run {rep}: rendered in {t:.0} ms (browser process {wall:.2} s)");
        ms.push(t);
    }
    ms.sort_by(f64::total_cmp);
    let median = ms[ms.len() / 2];
    let verdict = if median < 2000.0 { "meets" } else { "MISSES" };
    println!(
        "{} entries: median render {median:.0} ms (min {:.0}, max {:.0}) over {reps} runs; {verdict} the 2 000 ms target",
        best.len(),
        ms[0],
        ms[ms.len() - 1]
    );
}
