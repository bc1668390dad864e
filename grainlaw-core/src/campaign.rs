//! `grainlaw campaign PLAN.toml`: a sweep of independent scenario runs, run in parallel on the
//! local cores or as shares of a cluster job array, resumable, then merged and fitted.
//!
//! A plan is TOML (`docs/cli.md` §9):
//!
//! ```toml
//! scenario = "shear-cell"            # a built-in name, or a scenario TOML (relative to the plan)
//! [set]                              # fixed overrides, the keys of `--set`
//! grains = 120
//! [sweep]                            # each key a list of values; the runs are their product
//! seed = [1, 2, 3]
//! inertial_numbers = [[0.01, 0.02], [0.05, 0.1]]   # a list-valued key: a list of lists
//! ```
//!
//! The runs are the Cartesian product of the `[sweep]` lists, keys in sorted order, the last key
//! varying fastest; run `k` (0-based) goes to `OUT/runs/kkkk/` and is an ordinary `grainlaw run`
//! (a child process of this one, `-q`, its stderr in `OUT/runs/kkkk.log`), so that every run has
//! its own checkpoint, `summary.json` and exit status. A run whose `summary.json` exists is
//! finished and never redone; one with a checkpoint is resumed (`run --resume`). `--task K --of
//! N` runs only the runs `k` with `k mod N = K − 1`, so the same plan runs unchanged as a Slurm
//! job array (`--task $SLURM_ARRAY_TASK_ID --of $SLURM_ARRAY_TASK_COUNT`) or under GNU parallel.
//!
//! Collecting (`--collect`, or at the end of a campaign run without `--task`) needs every run
//! finished. It writes `campaign.csv` (one row per run: its swept values, exit status, verdict
//! and every numeric `summary.json` key), `campaign_stats.csv` (per combination of the swept
//! keys other than `seed`: mean and standard error over the seeds of every numeric key), and
//! merges the per-run tables a law can be fitted to (`rheology.csv` → μ(I), φ(I)) over the runs
//! whose exit status is 0, then fits them with the same code as `grainlaw fit`, and draws
//! `rheology.png` (μ(I), φ(I) over every point, with the merged laws and their bands).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Instant;

use toml::{Table, Value};

use crate::error::{CliError, Result};
use crate::fit_cmd::merged_table;
use crate::output::dir::write_atomic;
use crate::scenarios::rheology_fit::{FittedCurve, MeasuredPoint, RheologyFigure};

/// A parsed campaign plan.
#[derive(Debug, Clone, PartialEq)]
pub struct Plan {
    /// The scenario: a built-in name, or the absolute path of a scenario TOML.
    pub scenario: String,
    /// Fixed overrides, as `KEY=VALUE` arguments of `--set`.
    pub set: Vec<String>,
    /// Swept keys (sorted) and their values.
    pub sweep: Vec<(String, Vec<Value>)>,
}

/// One run of a campaign.
#[derive(Debug, Clone, PartialEq)]
pub struct RunSpec {
    /// Index in the Cartesian product (0-based).
    pub index: usize,
    /// The swept keys and this run's values (as TOML text).
    pub swept: Vec<(String, String)>,
    /// Every `--set` argument of the run: the plan's `[set]`, then the swept values.
    pub sets: Vec<String>,
}

fn plan_error(plan: &Path, reason: impl Into<String>) -> CliError {
    CliError::Input {
        path: plan.display().to_string(),
        reason: reason.into(),
    }
}

/// The dotted key `prefix.k` (`k` alone at the top level).
fn dotted(prefix: &str, k: &str) -> String {
    if prefix.is_empty() {
        k.to_string()
    } else {
        format!("{prefix}.{k}")
    }
}

/// Flattens a `[set]` table into dotted `KEY=VALUE` arguments (a nested table is a dotted key).
fn flatten(prefix: &str, t: &Table, out: &mut Vec<String>) {
    for (k, v) in t {
        let key = dotted(prefix, k);
        match v {
            Value::Table(sub) => flatten(&key, sub, out),
            v => out.push(format!("{key}={v}")),
        }
    }
}

/// Reads and checks a plan: `scenario` (string), `[set]` (table), `[sweep]` (table of non-empty
/// lists); any other top-level key is refused, as is a key both set and swept.
pub fn read_plan(path: &Path) -> Result<Plan> {
    let text = std::fs::read_to_string(path).map_err(|e| CliError::Io {
        path: path.display().to_string(),
        reason: e.to_string(),
    })?;
    parse_plan(&text, path)
}

/// [`read_plan`] on the plan's text (`path` names it in messages and anchors a relative
/// scenario file).
pub fn parse_plan(text: &str, path: &Path) -> Result<Plan> {
    let table: Table = text
        .parse()
        .map_err(|e: toml::de::Error| plan_error(path, e.message().to_string()))?;
    for k in table.keys() {
        if !matches!(k.as_str(), "scenario" | "set" | "sweep") {
            return Err(plan_error(
                path,
                format!("unknown key `{k}` (a plan has `scenario`, `[set]` and `[sweep]`)"),
            ));
        }
    }
    let scenario = match table.get("scenario") {
        Some(Value::String(s)) if !s.trim().is_empty() => s.trim().to_string(),
        Some(_) => {
            return Err(plan_error(
                path,
                "key `scenario`: expected a non-empty string",
            ))
        }
        None => {
            return Err(plan_error(
                path,
                "key `scenario` is missing (a built-in name or a scenario TOML file)",
            ))
        }
    };
    let scenario = if scenario.ends_with(".toml") {
        let base = path.parent().unwrap_or(Path::new("."));
        let p = base.join(&scenario);
        let p = p
            .canonicalize()
            .map_err(|e| plan_error(path, format!("key `scenario`: {}: {e}", p.display())))?;
        p.display().to_string()
    } else {
        scenario
    };
    let mut set = Vec::new();
    match table.get("set") {
        Some(Value::Table(t)) => flatten("", t, &mut set),
        Some(_) => return Err(plan_error(path, "key `set`: expected a table")),
        None => {}
    }
    let mut sweep = Vec::new();
    match table.get("sweep") {
        Some(Value::Table(t)) => {
            let mut flat = Vec::new();
            flatten_sweep("", t, &mut flat, path)?;
            sweep = flat;
        }
        Some(_) => return Err(plan_error(path, "key `sweep`: expected a table")),
        None => {}
    }
    sweep.sort_by(|a, b| a.0.cmp(&b.0));
    for (k, _) in &sweep {
        if set
            .iter()
            .any(|s| s.split_once('=').map(|p| p.0) == Some(k))
        {
            return Err(plan_error(
                path,
                format!("key `{k}` is both in [set] and in [sweep]"),
            ));
        }
    }
    Ok(Plan {
        scenario,
        set,
        sweep,
    })
}

fn flatten_sweep(
    prefix: &str,
    t: &Table,
    out: &mut Vec<(String, Vec<Value>)>,
    path: &Path,
) -> Result<()> {
    for (k, v) in t {
        let key = dotted(prefix, k);
        match v {
            Value::Table(sub) => flatten_sweep(&key, sub, out, path)?,
            Value::Array(a) if !a.is_empty() => out.push((key, a.clone())),
            Value::Array(_) => {
                return Err(plan_error(
                    path,
                    format!("[sweep] key `{key}`: empty list (give at least one value)"),
                ))
            }
            _ => {
                return Err(plan_error(
                    path,
                    format!(
                        "[sweep] key `{key}`: expected a list of values (a list-valued key is swept with a list of lists)"
                    ),
                ))
            }
        }
    }
    Ok(())
}

/// The runs of a plan: the Cartesian product of the swept lists, the last key varying fastest.
pub fn expand(plan: &Plan) -> Vec<RunSpec> {
    let total: usize = plan.sweep.iter().map(|(_, v)| v.len()).product();
    (0..total)
        .map(|index| {
            let mut rest = index;
            let mut picks = vec![0usize; plan.sweep.len()];
            for (j, (_, vals)) in plan.sweep.iter().enumerate().rev() {
                picks[j] = rest % vals.len();
                rest /= vals.len();
            }
            let swept: Vec<(String, String)> = plan
                .sweep
                .iter()
                .zip(&picks)
                .map(|((k, vals), &p)| (k.clone(), vals[p].to_string()))
                .collect();
            let mut sets = plan.set.clone();
            sets.extend(swept.iter().map(|(k, v)| format!("{k}={v}")));
            RunSpec { index, swept, sets }
        })
        .collect()
}

/// The runs of share `task` (1-based) of `of`: those whose index `k` has `k mod of = task − 1`.
pub fn share(runs: &[RunSpec], task: usize, of: usize) -> Vec<RunSpec> {
    runs.iter()
        .filter(|r| r.index % of == task - 1)
        .cloned()
        .collect()
}

/// The directory of run `index`.
pub fn run_dir(out: &Path, index: usize) -> PathBuf {
    out.join("runs").join(format!("{index:04}"))
}

/// Where a run stands.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RunState {
    /// `summary.json` written: finished (with the exit status recorded, if any).
    Finished(Option<i32>),
    /// A checkpoint is there: resumable.
    Checkpointed,
    /// Not started, or started and failed without a checkpoint.
    New,
}

/// The state of run `index` in `out`.
pub fn run_state(out: &Path, index: usize) -> RunState {
    let dir = run_dir(out, index);
    if dir.join("summary.json").is_file() {
        let code = std::fs::read_to_string(out.join("runs").join(format!("{index:04}.exit")))
            .ok()
            .and_then(|s| s.trim().parse().ok());
        RunState::Finished(code)
    } else if crate::checkpoint::file_of(&dir).is_file() {
        RunState::Checkpointed
    } else {
        RunState::New
    }
}

/// The options of `grainlaw campaign`.
#[derive(Debug, Clone)]
pub struct CampaignArgs {
    /// The plan file.
    pub plan: PathBuf,
    /// The campaign directory (default `grainlaw-out/campaign-STEM`).
    pub out: Option<PathBuf>,
    /// This share (1-based) of `of`.
    pub task: Option<usize>,
    /// Number of shares.
    pub of: Option<usize>,
    /// Only merge and fit.
    pub collect: bool,
    /// Runs at once (default: the cores available).
    pub jobs: Option<usize>,
}

/// `grainlaw campaign`: checks the plan and every run's overrides before anything runs, runs
/// the share, then collects when the whole plan was run here.
pub fn campaign(args: CampaignArgs) -> Result<()> {
    let plan = read_plan(&args.plan)?;
    let out = args.out.clone().unwrap_or_else(|| {
        let stem = args
            .plan
            .file_stem()
            .map(|s| s.to_string_lossy().to_string())
            .unwrap_or_else(|| "plan".into());
        PathBuf::from("grainlaw-out").join(format!("campaign-{stem}"))
    });
    let runs = expand(&plan);
    // Every run's overrides are checked here (the scenario is loaded, not run): a bad key or
    // value in the plan is one line, before any run starts.
    for r in &runs {
        crate::scenarios::registry::load(&plan.scenario, &r.sets).map_err(|e| {
            plan_error(
                &args.plan,
                format!("run {:04} ({}): {e}", r.index, describe(r)),
            )
        })?;
    }
    let (task, of) = match (args.task, args.of) {
        (None, None) => (1, 1),
        (Some(k), Some(n)) if n >= 1 && (1..=n).contains(&k) => (k, n),
        (Some(k), Some(n)) => {
            return Err(CliError::Usage(format!(
                "--task {k} --of {n}: expected 1 ≤ K ≤ N"
            )))
        }
        _ => {
            return Err(CliError::Usage(
                "--task and --of go together (--task K --of N)".into(),
            ))
        }
    };
    if args.collect && args.task.is_some() {
        return Err(CliError::Usage(
            "--collect merges the whole campaign: it takes no --task/--of".into(),
        ));
    }
    prepare_dir(&out, &args.plan, &plan)?;
    write_index(&out, &plan, &runs)?;
    if !args.collect {
        let mine = share(&runs, task, of);
        let jobs = args.jobs.unwrap_or_else(|| {
            std::thread::available_parallelism()
                .map(|n| n.get())
                .unwrap_or(1)
        });
        if jobs == 0 {
            return Err(CliError::Usage("--jobs must be at least 1".into()));
        }
        execute(&out, &plan, &mine, jobs)?;
        if of > 1 {
            println!(
                "share {task} of {of} done; when every share is done: grainlaw campaign {} --out {} --collect",
                args.plan.display(),
                out.display()
            );
            return Ok(());
        }
    }
    collect(&out, &plan, &runs)
}

fn describe(r: &RunSpec) -> String {
    if r.swept.is_empty() {
        "no swept key".into()
    } else {
        r.swept
            .iter()
            .map(|(k, v)| format!("{k}={v}"))
            .collect::<Vec<_>>()
            .join(", ")
    }
}

/// Creates the campaign directory, or checks that an existing one holds this plan (the plan's
/// parsed content, not its text, is compared: comments and layout may change).
fn prepare_dir(out: &Path, plan_path: &Path, plan: &Plan) -> Result<()> {
    if out.exists() && !out.is_dir() {
        return Err(CliError::Usage(format!(
            "--out {}: is a file, not a directory",
            out.display()
        )));
    }
    let copy = out.join("plan.toml");
    if copy.is_file() {
        let before = read_plan(&copy).ok();
        // The copy's relative scenario path was resolved when it was written: compare the
        // resolved plans.
        if before.as_ref() != Some(plan) {
            return Err(CliError::Usage(format!(
                "--out {}: holds a campaign of another plan (its plan.toml differs from {}): choose another directory or remove it",
                out.display(),
                plan_path.display()
            )));
        }
        return Ok(());
    }
    if out.join("scenario.toml").is_file() {
        return Err(CliError::Usage(format!(
            "--out {}: holds the outputs of a scenario run, not a campaign",
            out.display()
        )));
    }
    std::fs::create_dir_all(out.join("runs")).map_err(|e| CliError::Io {
        path: out.display().to_string(),
        reason: e.to_string(),
    })?;
    // The copy carries the resolved scenario so that it reads back to the same plan.
    let mut text = format!("scenario = {}\n", Value::String(plan.scenario.clone()));
    if !plan.set.is_empty() {
        text.push_str("[set]\n");
        for s in &plan.set {
            if let Some((k, v)) = s.split_once('=') {
                text.push_str(&format!("{} = {v}\n", quote_dotted(k)));
            }
        }
    }
    if !plan.sweep.is_empty() {
        text.push_str("[sweep]\n");
        for (k, vals) in &plan.sweep {
            text.push_str(&format!(
                "{} = {}\n",
                quote_dotted(k),
                Value::Array(vals.clone())
            ));
        }
    }
    write_atomic(&copy, text.as_bytes())
}

/// A dotted key as TOML dotted-key syntax (each part bare when it can be).
fn quote_dotted(k: &str) -> String {
    k.split('.')
        .map(|p| {
            if p.chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
            {
                p.to_string()
            } else {
                format!("\"{p}\"")
            }
        })
        .collect::<Vec<_>>()
        .join(".")
}

/// `runs.csv`: one row per run, its index, directory and swept values.
fn write_index(out: &Path, plan: &Plan, runs: &[RunSpec]) -> Result<()> {
    let mut w = csv::Writer::from_writer(Vec::new());
    let mut head = vec!["run".to_string(), "dir".to_string()];
    head.extend(plan.sweep.iter().map(|(k, _)| k.clone()));
    w.write_record(&head).map_err(csv_err)?;
    for r in runs {
        let mut row = vec![format!("{:04}", r.index), format!("runs/{:04}", r.index)];
        row.extend(r.swept.iter().map(|(_, v)| v.clone()));
        w.write_record(&row).map_err(csv_err)?;
    }
    let bytes = w.into_inner().map_err(|e| CliError::Io {
        path: "runs.csv".into(),
        reason: e.to_string(),
    })?;
    write_atomic(&out.join("runs.csv"), &bytes)
}

fn csv_err(e: csv::Error) -> CliError {
    CliError::Io {
        path: "csv".into(),
        reason: e.to_string(),
    }
}

/// The executable that runs each scenario: this program.
fn grainlaw_exe() -> Result<PathBuf> {
    if let Ok(p) = std::env::var("GRAINLAW_EXE") {
        return Ok(PathBuf::from(p));
    }
    std::env::current_exe().map_err(|e| CliError::Io {
        path: "grainlaw executable".into(),
        reason: e.to_string(),
    })
}

/// Runs `runs` (skipping finished ones, resuming checkpointed ones), `jobs` at a time. A stop
/// request (Ctrl-C, SIGTERM to the process group: every child receives it and checkpoints)
/// starts no new run and returns [`CliError::Interrupted`]-like exit 130 once the running ones
/// have stopped.
fn execute(out: &Path, plan: &Plan, runs: &[RunSpec], jobs: usize) -> Result<()> {
    let exe = grainlaw_exe()?;
    let stop = Arc::new(AtomicBool::new(false));
    {
        let flag = stop.clone();
        let _ = ctrlc::set_handler(move || {
            if !flag.swap(true, Ordering::SeqCst) {
                eprintln!("warning: stop requested: the running runs write their checkpoints; no new run starts");
            }
        });
    }
    let todo: Vec<&RunSpec> = runs
        .iter()
        .filter(|r| !matches!(run_state(out, r.index), RunState::Finished(_)))
        .collect();
    let skipped = runs.len() - todo.len();
    if skipped > 0 {
        println!("{skipped} run(s) already finished: not redone");
    }
    let next = AtomicUsize::new(0);
    let failures: Mutex<Vec<String>> = Mutex::new(Vec::new());
    let interrupted = AtomicBool::new(false);
    std::thread::scope(|s| {
        for _ in 0..jobs.min(todo.len().max(1)) {
            s.spawn(|| loop {
                if stop.load(Ordering::SeqCst) {
                    break;
                }
                let i = next.fetch_add(1, Ordering::SeqCst);
                let Some(r) = todo.get(i) else { break };
                match run_one(&exe, out, plan, r) {
                    Ok((code, secs)) => {
                        let what = match code {
                            0 => "ok".to_string(),
                            3 => "finished, a result refused (exit 3)".to_string(),
                            130 => {
                                interrupted.store(true, Ordering::SeqCst);
                                "stopped, checkpoint written".to_string()
                            }
                            c => {
                                failures
                                    .lock()
                                    .unwrap_or_else(|p| p.into_inner())
                                    .push(format!("{:04}", r.index));
                                format!("failed (exit {c}): see runs/{:04}.log", r.index)
                            }
                        };
                        println!("run {:04} [{}]: {what} ({secs:.1} s)", r.index, describe(r));
                    }
                    Err(e) => {
                        failures
                            .lock()
                            .unwrap_or_else(|p| p.into_inner())
                            .push(format!("{:04}: {}", r.index, e.one_line()));
                    }
                }
            });
        }
    });
    let failures = failures.into_inner().unwrap_or_else(|p| p.into_inner());
    if stop.load(Ordering::SeqCst) || interrupted.load(Ordering::SeqCst) {
        return Err(CliError::CampaignStopped {
            dir: out.display().to_string(),
        });
    }
    if !failures.is_empty() {
        return Err(CliError::Input {
            path: out.display().to_string(),
            reason: format!(
                "{} run(s) failed: {} (their logs are in runs/; run the campaign again to retry them)",
                failures.len(),
                failures.join(", ")
            ),
        });
    }
    Ok(())
}

/// Runs (or resumes) one run as a child `grainlaw run … -q`; returns its exit code and time.
fn run_one(exe: &Path, out: &Path, plan: &Plan, r: &RunSpec) -> Result<(i32, f64)> {
    let dir = run_dir(out, r.index);
    let log = out.join("runs").join(format!("{:04}.log", r.index));
    let mut cmd = Command::new(exe);
    match run_state(out, r.index) {
        RunState::Checkpointed => {
            cmd.arg("run").arg("--resume").arg(&dir).arg("-q");
        }
        _ => {
            cmd.arg("run")
                .arg(&plan.scenario)
                .arg("--out")
                .arg(&dir)
                .arg("-q");
            for s in &r.sets {
                cmd.arg("--set").arg(s);
            }
        }
    }
    let log_file = std::fs::File::create(&log).map_err(|e| CliError::Io {
        path: log.display().to_string(),
        reason: e.to_string(),
    })?;
    cmd.stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::from(log_file));
    let t0 = Instant::now();
    let status = cmd.status().map_err(|e| CliError::Io {
        path: exe.display().to_string(),
        reason: e.to_string(),
    })?;
    let code = status.code().unwrap_or(2);
    if dir.join("summary.json").is_file() {
        write_atomic(
            &out.join("runs").join(format!("{:04}.exit", r.index)),
            format!("{code}\n").as_bytes(),
        )?;
    }
    Ok((code, t0.elapsed().as_secs_f64()))
}

/// The numeric leaves of a summary, with dotted keys for nested objects.
fn numeric_leaves(prefix: &str, v: &serde_json::Value, out: &mut BTreeMap<String, f64>) {
    match v {
        serde_json::Value::Number(n) => {
            if let Some(x) = n.as_f64() {
                out.insert(prefix.to_string(), x);
            }
        }
        serde_json::Value::Object(m) => {
            for (k, v) in m {
                numeric_leaves(&dotted(prefix, k), v, out);
            }
        }
        _ => {}
    }
}

/// What one finished run left.
struct Finished {
    spec: RunSpec,
    code: Option<i32>,
    verdict: Option<String>,
    numbers: BTreeMap<String, f64>,
}

/// A law's name and the simpler form to fit when the data do not support it.
type LawWithFallback = (&'static str, Option<&'static str>);

/// Tables a law can be fitted to, merged over the runs, and the laws fitted to them, each with
/// the simpler form fitted instead when the data do not support it (the form `grainlaw fit`
/// names in its refusal).
const MERGED: &[(&str, &[LawWithFallback])] = &[(
    "rheology.csv",
    &[("mu-i", Some("mu-i-linear")), ("phi-i", None)],
)];

/// `--collect`: the campaign tables, the merged histories and their fits (stages: every run
/// finished → their summaries read → `campaign.csv`, `campaign_stats.csv`, the runouts → the
/// merged tables and their fits).
fn collect(out: &Path, plan: &Plan, runs: &[RunSpec]) -> Result<()> {
    check_all_finished(out, runs)?;
    let done = read_finished(out, runs)?;
    write_campaign_csv(out, plan, &done)?;
    write_stats_csv(out, plan, &done)?;
    write_runouts(out, &done)?;
    println!(
        "campaign: {} runs collected into {}/campaign.csv and campaign_stats.csv",
        done.len(),
        out.display()
    );
    // Merged tables: only runs that passed (exit 0, verdict ok when present).
    let passed: Vec<&Finished> = done
        .iter()
        .filter(|f| f.code.unwrap_or(0) == 0 && f.verdict.as_deref().is_none_or(|v| v == "ok"))
        .collect();
    let left_out: Vec<String> = done
        .iter()
        .filter(|f| !passed.iter().any(|p| p.spec.index == f.spec.index))
        .map(|f| format!("{:04}", f.spec.index))
        .collect();
    if !left_out.is_empty() {
        println!(
            "runs with a result refused or suspect (their points that passed their own checks are merged): {}",
            abbreviate(&left_out)
        );
    }
    let mut refused = Vec::new();
    for (table, laws) in MERGED {
        refused.extend(merge_and_fit(out, table, laws, &done, &passed)?);
    }
    if !refused.is_empty() {
        return Err(CliError::FitRefused {
            path: out.display().to_string(),
            reason: format!("merged fits refused: {}", refused.join(", ")),
        });
    }
    Ok(())
}

/// Refuses to collect a partial campaign: every run must be finished.
fn check_all_finished(out: &Path, runs: &[RunSpec]) -> Result<()> {
    let missing: Vec<String> = runs
        .iter()
        .filter(|r| !matches!(run_state(out, r.index), RunState::Finished(_)))
        .map(|r| format!("{:04}", r.index))
        .collect();
    if !missing.is_empty() {
        return Err(CliError::Input {
            path: out.display().to_string(),
            reason: format!(
                "{} of {} runs are not finished ({}): nothing is merged from a partial campaign",
                missing.len(),
                runs.len(),
                abbreviate(&missing)
            ),
        });
    }
    Ok(())
}

/// Each run's exit code, verdict and the numbers of its `summary.json`.
fn read_finished(out: &Path, runs: &[RunSpec]) -> Result<Vec<Finished>> {
    let mut done = Vec::new();
    for r in runs {
        let path = run_dir(out, r.index).join("summary.json");
        let text = std::fs::read_to_string(&path).map_err(|e| CliError::Io {
            path: path.display().to_string(),
            reason: e.to_string(),
        })?;
        let json: serde_json::Value = serde_json::from_str(&text).map_err(|e| CliError::Input {
            path: path.display().to_string(),
            reason: e.to_string(),
        })?;
        let mut numbers = BTreeMap::new();
        numeric_leaves("", &json, &mut numbers);
        let code = match run_state(out, r.index) {
            RunState::Finished(c) => c,
            _ => None,
        };
        done.push(Finished {
            spec: r.clone(),
            code,
            verdict: json
                .get("verdict")
                .and_then(|v| v.as_str())
                .map(String::from),
            numbers,
        });
    }
    Ok(done)
}

/// Runs of `column-collapse`: the runout against the aspect ratio, r_∞(a).
fn write_runouts(out: &Path, done: &[Finished]) -> Result<()> {
    let collapses: Vec<crate::scenarios::column_collapse::CampaignRun> = done
        .iter()
        .filter(|f| f.numbers.contains_key("column.runout_m"))
        .map(|f| crate::scenarios::column_collapse::CampaignRun {
            index: f.spec.index,
            numbers: &f.numbers,
            verdict: f.verdict.clone().unwrap_or_default(),
            code: f.code,
        })
        .collect();
    if !collapses.is_empty() {
        let mut dir = crate::output::OutputDir::open(out)?;
        crate::scenarios::column_collapse::write_runout(&mut dir, &collapses)?;
        println!(
            "runout of {} column collapses against the aspect ratio: {}/runout.csv and runout.png",
            collapses.len(),
            out.display()
        );
    }
    Ok(())
}

/// Merges `table` over the runs and fits `laws` to it (the rheology's figure too); returns the
/// laws refused. A table with a `point_verdict` column is judged row by row: its passed rows
/// are merged from every run that completed (exit 0 or 3); another table only from the runs
/// that `passed` as a whole.
fn merge_and_fit(
    out: &Path,
    table: &str,
    laws: &[LawWithFallback],
    done: &[Finished],
    passed: &[&Finished],
) -> Result<Vec<String>> {
    let files: Vec<(usize, PathBuf)> = done
        .iter()
        .filter(|f| {
            let p = run_dir(out, f.spec.index).join(table);
            if has_point_verdict(&p) {
                matches!(f.code, None | Some(0) | Some(3))
            } else {
                passed.iter().any(|q| q.spec.index == f.spec.index)
            }
        })
        .map(|f| (f.spec.index, run_dir(out, f.spec.index).join(table)))
        .filter(|(_, p)| p.is_file())
        .collect();
    if files.is_empty() {
        return Ok(Vec::new());
    }
    let merged = out.join(table);
    merge_tables(&files, &merged)?;
    println!(
        "merged {table} of {} runs into {}",
        files.len(),
        merged.display()
    );
    let mut refused = Vec::new();
    let mut fitted_laws = Vec::new();
    for (law, simpler) in laws {
        match fit_with_fallback(out, &merged, law, *simpler)? {
            Some(cal) => fitted_laws.push(cal),
            None => refused.push(law.to_string()),
        }
    }
    if table == "rheology.csv" {
        let figure = write_rheology_figure(out, &files, &fitted_laws)?;
        println!("figure of the merged points and laws: {}", figure.display());
    }
    Ok(refused)
}

/// Fits `law` to the merged table, else its `simpler` form (`None` when both are refused). On
/// merged data a fit that cannot be made (too few points passed their checks, a column left
/// empty) is a refusal of the campaign's result, not bad input.
fn fit_with_fallback(
    out: &Path,
    merged: &Path,
    law: &'static str,
    simpler: Option<&'static str>,
) -> Result<Option<identify::CalibratedLaw>> {
    let mut tried = vec![law];
    tried.extend(simpler.iter());
    for l in tried {
        let law_out = out.join(format!("{}_law.json", l.replace('-', "_")));
        match crate::fit_cmd::fit(l, merged, Some(&law_out)) {
            Ok(cal) => return Ok(Some(cal)),
            Err(e @ (CliError::FitRefused { .. } | CliError::Input { .. })) => {
                println!("{l}: refused: {}", e.one_line());
            }
            Err(e) => return Err(e),
        }
    }
    Ok(None)
}

/// The points of the runs' `rheology.csv` tables, for the campaign's figure: `(μ points,
/// φ points)`, each point with its standard errors when the table has them and whether it
/// passed its own checks (`point_verdict` 0; a table without that column passes whole).
fn rheology_points(files: &[(usize, PathBuf)]) -> Result<(Vec<MeasuredPoint>, Vec<MeasuredPoint>)> {
    let (mut mu, mut phi) = (Vec::new(), Vec::new());
    for (_, path) in files {
        let text = std::fs::read_to_string(path).map_err(|e| CliError::io(path, e))?;
        let table = identify::data::Table::parse_csv(&text, &path.display().to_string())?;
        let column = |name: &str| table.optional_column(name);
        let i = table.column("I")?;
        let nan = vec![f64::NAN; i.len()];
        let i_se = column("I_std_error")?.unwrap_or_else(|| nan.clone());
        let passed: Vec<bool> = column(identify::user_fit::POINT_VERDICT)?
            .map(|v| v.iter().map(|v| *v == 0.0).collect())
            .unwrap_or_else(|| vec![true; i.len()]);
        for (name, into) in [("mu", &mut mu), ("phi", &mut phi)] {
            let Some(values) = column(name)? else {
                continue;
            };
            let se = column(&format!("{name}_std_error"))?.unwrap_or_else(|| nan.clone());
            for k in 0..i.len() {
                into.push(MeasuredPoint {
                    i: i[k],
                    i_std_error: i_se[k],
                    value: values[k],
                    std_error: se[k],
                    passed: passed[k],
                });
            }
        }
    }
    Ok((mu, phi))
}

/// The fitted curve of a calibrated law over `[lo, hi]`, with its pointwise 95 % band by the
/// delta method on the law's covariance ([`crate::scenarios::common::delta_band`], with the
/// law's `t` quantile at its confidence and degrees of freedom); `linear` when the law is
/// linear in `I` (`mu-i-linear`, `phi-i`, `phi-i-linear`).
fn law_curve(cal: &identify::CalibratedLaw, (lo, hi): (f64, f64)) -> Result<FittedCurve> {
    let linear = cal.law != "mu-i";
    let order: Vec<String> = match &cal.covariance {
        Some(c) => c.order.clone(),
        None => Vec::new(),
    };
    let cov = cal
        .covariance
        .as_ref()
        .map(|c| c.matrix.clone())
        .unwrap_or_default();
    let p: Vec<f64> = order
        .iter()
        .map(|n| cal.parameter(n))
        .collect::<identify::Result<_>>()?;
    // the law with the parameters `q` (in the covariance's order) at `x`
    let eval = |q: &[f64], x: f64| -> f64 {
        let mut c = cal.clone();
        for (name, v) in order.iter().zip(q) {
            if let Some(par) = c.parameters.iter_mut().find(|par| &par.name == name) {
                par.estimate.value = *v;
            }
        }
        c.to_law().map_or(f64::NAN, |l| l.evaluate(x))
    };
    cal.to_law()?;
    let t = identify::stats::t_critical(cal.fit.confidence, cal.fit.dof.max(1));
    let xs = crate::scenarios::rheology_fit::curve_abscissae(lo, hi, !linear);
    Ok(FittedCurve {
        label: format!("{}: {}", cal.law, cal.expression.formula),
        linear,
        band: crate::scenarios::common::delta_band(&p, &cov, t, &xs, eval),
    })
}

/// Draws `rheology.png` in the campaign directory: μ(I) and φ(I) over every point of the
/// merged runs (those that failed their own checks hollow, as left out of the fits), with the
/// laws fitted to the merged table (`laws`) and their 95 % bands over the fitted points' range
/// ([`crate::scenarios::rheology_fit::rheology_plot`], the figure of a single run). Returns the
/// file's path.
fn write_rheology_figure(
    out: &Path,
    files: &[(usize, PathBuf)],
    laws: &[identify::CalibratedLaw],
) -> Result<PathBuf> {
    let (mu, phi) = rheology_points(files)?;
    let fitted_range = |pts: &[MeasuredPoint]| {
        crate::scenarios::rheology_fit::finite_range(pts.iter().filter(|p| p.passed).map(|p| p.i))
    };
    let curve = |names: &[&str], pts: &[MeasuredPoint]| -> Result<Option<FittedCurve>> {
        match (
            laws.iter().find(|l| names.contains(&l.law.as_str())),
            fitted_range(pts),
        ) {
            (Some(cal), Some(range)) => law_curve(cal, range).map(Some),
            _ => Ok(None),
        }
    };
    let runs = files.len();
    let plot = |title: &str, y_label: &str, colour, pts: &[MeasuredPoint], names: &[&str]| {
        let curve = curve(names, pts)?;
        let notes = if curve.is_none() {
            vec!["no law fitted to these points (refused: see the printed reason)".to_string()]
        } else {
            Vec::new()
        };
        Ok::<_, CliError>(crate::scenarios::rheology_fit::rheology_plot(
            &RheologyFigure {
                title: title.to_string(),
                y_label,
                colour,
                passed_label: format!("DEM, {runs} runs"),
                marked_label: "left out: failed its own checks",
                points: pts,
                curve,
                notes,
            },
        ))
    };
    let pmu = plot(
        "Friction law μ(I), the campaign's points",
        "μ = |σ_xy| / P",
        crate::plot::PALETTE[0],
        &mu,
        &["mu-i", "mu-i-linear"],
    )?;
    let mut pphi = plot(
        "Solid fraction φ(I), the campaign's points",
        "solid fraction φ",
        crate::plot::PALETTE[2],
        &phi,
        &["phi-i", "phi-i-linear"],
    )?;
    pphi.legend = crate::plot::xy::LegendAt::UpperRight;
    let mut dir = crate::output::OutputDir::open(out)?;
    crate::plot::xy::draw_row(&mut dir, "rheology.png", &[pmu, pphi], (1500, 650))?;
    Ok(out.join("rheology.png"))
}

fn abbreviate(list: &[String]) -> String {
    if list.len() <= 8 {
        list.join(", ")
    } else {
        format!("{}, … ({} in all)", list[..8].join(", "), list.len())
    }
}

fn write_campaign_csv(out: &Path, plan: &Plan, done: &[Finished]) -> Result<()> {
    let keys: BTreeSet<&String> = done.iter().flat_map(|f| f.numbers.keys()).collect();
    let mut w = csv::Writer::from_writer(Vec::new());
    let mut head = vec!["run".to_string()];
    head.extend(plan.sweep.iter().map(|(k, _)| k.clone()));
    head.push("exit_status".into());
    head.push("verdict".into());
    head.extend(keys.iter().map(|k| k.to_string()));
    w.write_record(&head).map_err(csv_err)?;
    for f in done {
        let mut row = vec![format!("{:04}", f.spec.index)];
        row.extend(f.spec.swept.iter().map(|(_, v)| v.clone()));
        row.push(f.code.map(|c| c.to_string()).unwrap_or_default());
        row.push(f.verdict.clone().unwrap_or_default());
        row.extend(keys.iter().map(|k| {
            f.numbers
                .get(*k)
                .map(|x| format!("{x:e}"))
                .unwrap_or_default()
        }));
        w.write_record(&row).map_err(csv_err)?;
    }
    let bytes = w.into_inner().map_err(|e| CliError::Io {
        path: "campaign.csv".into(),
        reason: e.to_string(),
    })?;
    write_atomic(&out.join("campaign.csv"), &bytes)
}

/// Mean and standard error over the runs of each combination of the swept keys other than
/// `seed` (`s/√n`, `s` the sample standard deviation; empty when n = 1).
fn write_stats_csv(out: &Path, plan: &Plan, done: &[Finished]) -> Result<()> {
    let group_keys: Vec<&String> = plan
        .sweep
        .iter()
        .map(|(k, _)| k)
        .filter(|k| k.as_str() != "seed")
        .collect();
    let mut groups: BTreeMap<Vec<String>, Vec<&Finished>> = BTreeMap::new();
    for f in done {
        let g: Vec<String> = f
            .spec
            .swept
            .iter()
            .filter(|(k, _)| k != "seed")
            .map(|(_, v)| v.clone())
            .collect();
        groups.entry(g).or_default().push(f);
    }
    let mut w = csv::Writer::from_writer(Vec::new());
    let mut head: Vec<String> = group_keys.iter().map(|k| k.to_string()).collect();
    head.extend(["key", "n", "mean", "std_error"].map(String::from));
    w.write_record(&head).map_err(csv_err)?;
    for (g, members) in &groups {
        let keys: BTreeSet<&String> = members.iter().flat_map(|f| f.numbers.keys()).collect();
        for k in keys {
            if k == "seed" {
                continue;
            }
            let xs: Vec<f64> = members
                .iter()
                .filter_map(|f| f.numbers.get(k).copied())
                .collect();
            let (mean, se) = mean_and_std_error(&xs);
            let mut row = g.clone();
            row.push(k.clone());
            row.push(xs.len().to_string());
            row.push(format!("{mean:e}"));
            row.push(se.map(|s| format!("{s:e}")).unwrap_or_default());
            w.write_record(&row).map_err(csv_err)?;
        }
    }
    let bytes = w.into_inner().map_err(|e| CliError::Io {
        path: "campaign_stats.csv".into(),
        reason: e.to_string(),
    })?;
    write_atomic(&out.join("campaign_stats.csv"), &bytes)
}

/// Mean and standard error of the mean `s/√n` (None for fewer than two values).
pub fn mean_and_std_error(xs: &[f64]) -> (f64, Option<f64>) {
    let n = xs.len() as f64;
    let mean = xs.iter().sum::<f64>() / n;
    if xs.len() < 2 {
        return (mean, None);
    }
    let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, Some((var / n).sqrt()))
}

/// Whether a grainlaw CSV table has a `point_verdict` column (its header line).
fn has_point_verdict(path: &Path) -> bool {
    std::fs::read_to_string(path)
        .ok()
        .and_then(|t| {
            t.lines()
                .find(|l| !l.trim().is_empty() && !l.trim_start().starts_with('#'))
                .map(|h| h.split(',').any(|c| c.trim() == "point_verdict"))
        })
        .unwrap_or(false)
}

/// Concatenates per-run CSV tables written by grainlaw (same header) and adds a `run` column
/// ([`merged_table`]), into `merged`.
fn merge_tables(files: &[(usize, PathBuf)], merged: &Path) -> Result<()> {
    let (text, _) = merged_table(files, &merged.display().to_string(), "grainlaw campaign")?;
    write_atomic(merged, text.as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Per-run `rheology.csv` tables as `simple-shear` writes them, three runs, points on
    /// μ = 0.28 + I and φ = 0.80 − 0.25 I (within ±0.004 in a fixed pattern), with standard
    /// errors 0.01 (μ) and 0.001 (φ); run k's point k + 1 failed its own checks (and lies
    /// off the law: μ + 0.1).
    fn run_tables(dir: &Path) -> Vec<(usize, PathBuf)> {
        let is = [0.04, 0.07, 0.1, 0.15, 0.25];
        let wobble = [0.004, -0.003, 0.001, -0.004, 0.002, 0.003, -0.001];
        (0..3)
            .map(|k| {
                let mut t = String::from(
                    "# grain_diameter_m = 3e-3\n# grain_density_kg_m3 = 2.5e3\nI,I_std_error,mu,mu_std_error,phi,phi_std_error,P_Pa,point_verdict\n",
                );
                for (j, &i) in is.iter().enumerate() {
                    let w = wobble[(j + 2 * k) % wobble.len()];
                    let failed = j == k + 1;
                    let mu = 0.28 + i + w + if failed { 0.1 } else { 0.0 };
                    let phi = 0.80 - 0.25 * i - 0.5 * w;
                    t.push_str(&format!(
                        "{i},{},{mu},0.01,{phi},0.001,1000,{}\n",
                        0.01 * i,
                        u8::from(failed)
                    ));
                }
                let path = dir.join(format!("r{k}.csv"));
                std::fs::write(&path, t).unwrap();
                (k, path)
            })
            .collect()
    }

    /// The campaign's figure data: every point of every run, with its standard errors, those
    /// that failed their own checks marked; a law fitted to the merged table is drawn over
    /// the passed points' I range only, as a straight line (linear law, linear axis: evenly
    /// spaced abscissae, the values on μ_s + b I to 1e-12) with a band holding the line; and
    /// the figure file is written.
    #[test]
    fn the_figure_shows_all_points_and_the_merged_laws_over_their_range() {
        let dir = tempfile::tempdir().unwrap();
        let files = run_tables(dir.path());
        let (mu, phi) = rheology_points(&files).unwrap();
        assert_eq!((mu.len(), phi.len()), (15, 15));
        assert_eq!(mu.iter().filter(|p| !p.passed).count(), 3);
        assert!(mu
            .iter()
            .all(|p| p.std_error == 0.01 && p.i_std_error == 0.01 * p.i));
        assert!(phi.iter().all(|p| p.std_error == 0.001));
        let merged = dir.path().join("rheology.csv");
        merge_tables(&files, &merged).unwrap();
        let cal =
            crate::fit_cmd::fit("mu-i-linear", &merged, Some(&dir.path().join("l.json"))).unwrap();
        let range = crate::scenarios::rheology_fit::finite_range(
            mu.iter().filter(|p| p.passed).map(|p| p.i),
        )
        .unwrap();
        assert_eq!(range, (0.04, 0.25));
        let c = law_curve(&cal, range).unwrap();
        assert!(c.linear);
        let (mu_s, b) = (cal.parameter("mu_s").unwrap(), cal.parameter("b").unwrap());
        assert!(
            (mu_s - 0.28).abs() < 0.01 && (b - 1.0).abs() < 0.1,
            "{mu_s} {b}"
        );
        assert_eq!(c.band.first().unwrap().0, 0.04);
        assert!((c.band.last().unwrap().0 - 0.25).abs() < 1e-15);
        for w in c.band.windows(2) {
            assert!((w[1].0 - w[0].0 - 0.21 / 80.0).abs() < 1e-12);
        }
        for &(x, f, lo, hi) in &c.band {
            assert!((f - (mu_s + b * x)).abs() < 1e-12);
            assert!(lo < f && f < hi, "{lo} {f} {hi}");
        }
        let figure = write_rheology_figure(dir.path(), &files, &[cal]).unwrap();
        let png = std::fs::read(figure).unwrap();
        assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    }

    fn plan(text: &str) -> Result<Plan> {
        parse_plan(text, Path::new("plan.toml"))
    }

    #[test]
    fn product_last_key_fastest_and_shares_partition() {
        let p = plan(
            "scenario = \"rolling\"\n[set]\nduration = 0.1\n[sweep]\nseed = [1, 2, 3]\nfriction = [0.2, 0.5]\n",
        )
        .unwrap();
        let runs = expand(&p);
        assert_eq!(runs.len(), 6);
        // keys sorted: friction, seed; seed varies fastest
        assert_eq!(
            runs[0].swept,
            vec![
                ("friction".into(), "0.2".into()),
                ("seed".into(), "1".into())
            ]
        );
        assert_eq!(
            runs[4].swept,
            vec![
                ("friction".into(), "0.5".into()),
                ("seed".into(), "2".into())
            ]
        );
        assert_eq!(runs[4].sets, vec!["duration=0.1", "friction=0.5", "seed=2"]);
        let mut all: Vec<usize> = (1..=4)
            .flat_map(|k| share(&runs, k, 4).into_iter().map(|r| r.index))
            .collect();
        all.sort();
        assert_eq!(all, (0..6).collect::<Vec<_>>());
    }

    #[test]
    fn list_of_lists_and_nested_keys() {
        let p = plan(
            "scenario = \"shear-cell\"\n[set.grain]\nradius_mean = 1e-3\n[sweep]\ninertial_numbers = [[0.01, 0.02], [0.1]]\n",
        )
        .unwrap();
        assert_eq!(p.set, vec!["grain.radius_mean=0.001"]);
        let runs = expand(&p);
        assert_eq!(runs.len(), 2);
        assert_eq!(runs[0].sets[1], "inertial_numbers=[0.01, 0.02]");
    }

    #[test]
    fn bad_plans_name_the_key() {
        let e = plan("scenario = \"rolling\"\nsweep = 3\n").unwrap_err();
        assert!(e.one_line().contains("`sweep`"), "{}", e.one_line());
        let e = plan("scenario = \"rolling\"\n[sweep]\nseed = []\n").unwrap_err();
        assert!(e.one_line().contains("empty list"), "{}", e.one_line());
        let e = plan("scenario = \"rolling\"\n[sweep]\nseed = 3\n").unwrap_err();
        assert!(e.one_line().contains("list of values"), "{}", e.one_line());
        let e = plan("senario = \"rolling\"\n").unwrap_err();
        assert!(
            e.one_line().contains("unknown key `senario`"),
            "{}",
            e.one_line()
        );
        let e =
            plan("scenario = \"rolling\"\n[set]\nseed = 1\n[sweep]\nseed = [1, 2]\n").unwrap_err();
        assert!(e.one_line().contains("both"), "{}", e.one_line());
    }

    #[test]
    fn standard_error_of_known_sample() {
        // 1, 2, 3, 4: mean 2.5, s² = 5/3, se = sqrt(5/12)
        let (m, se) = mean_and_std_error(&[1.0, 2.0, 3.0, 4.0]);
        assert!((m - 2.5).abs() < 1e-15);
        assert!((se.unwrap() - (5.0f64 / 12.0).sqrt()).abs() < 1e-15);
        assert_eq!(mean_and_std_error(&[7.0]).1, None);
    }
}
