//! `stentkit sweep`: run a family of variants of a design on this machine (N worker processes) or as a Slurm
//! job array, `sweep collect` (sweep.csv and charts), `sweep status`, and `sweep task` (one variant: what each
//! worker and each array task runs). The sweep folder and the variants' states are [`crate::sweep`]'s.
//!
//! Local workers are threads of the sweep's process, each running one variant at a time in process through
//! [`crate::run`] on a rayon pool of the threads per run, its messages appended to the variant's `log.txt` (as
//! `stentkit sweep task DIR INDEX`, which a Slurm array task runs, prints them). On SIGINT, SIGTERM or SIGHUP no
//! new variant starts and each running one is asked once to stop (as by one SIGTERM: it finishes its files and
//! writes a checkpoint); the sweep waits for them, collects, and exits with status 130. A signal while the
//! designs are read for the disk estimate ends the sweep with nothing written, one while the variants are
//! prepared ends it after the variant in hand (status 130 both). A rerun continues.

use super::{BadInput, Interrupted, signals};
use crate::design::size::human_bytes;
use crate::math::Real;
use crate::run::{Console, Interrupt};
use crate::sweep::collect::{Collected, collect};
use crate::sweep::slurm::{self, Job, SlurmOptions};
use crate::sweep::{Parameter, Plan, Prepared, SweepDir, VariantState, disk};
use anyhow::Context as _;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// What `stentkit sweep DESIGN …` was asked.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct SweepOptions {
    /// The swept `--set` arguments (`PATH=V1,V2,…` or `PATH=START:STOP:STEP`).
    pub sets: Vec<String>,
    /// Pair the k-th values instead of the cartesian product.
    pub zip: bool,
    /// The bench test every variant runs instead of its design's run.
    pub bench: Option<crate::bench::Test>,
    /// The sweep folder.
    pub output: PathBuf,
    /// Local workers (default: cores / threads per run).
    pub jobs: Option<usize>,
    /// Threads of each run.
    pub threads_per_run: usize,
    /// Rerun failed variants.
    pub retry_failed: bool,
    /// Times of the recovery-ratio columns (default: halfway through the recovery and the end).
    pub at: Option<Vec<Real>>,
    /// Submit to Slurm instead of running here.
    pub slurm: Option<SlurmOptions>,
    /// With `slurm`: write the batch script only.
    pub dry_run: bool,
}

/// Plans the sweep, checks the folder and the disk, writes its folder and runs (or submits) the variants that
/// need it. Nothing is written before the plan, the folder, the values headed for a batch script and the disk
/// estimate are accepted; a signal before then leaves nothing, a signal while the variants are prepared stops
/// there (the same command continues: [`SweepDir::prepare`]).
///
/// # Errors
/// [`BadInput`] for arguments, a folder or a disk refused, [`Interrupted`] when stopped by a signal, an error
/// when variants failed (after the table is written) or Slurm refused the job.
pub(crate) fn run(design: &Path, options: SweepOptions) -> anyhow::Result<()> {
    signals::install_with(signals::SWEEP);
    let parameters = options
        .sets
        .iter()
        .map(|s| Parameter::parse(s))
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| BadInput(e.to_string()))?;
    let mut plan =
        Plan::new(design, parameters, options.zip).map_err(|e| BadInput(e.to_string()))?;
    plan.bench = options.bench;
    let dir = SweepDir {
        dir: options.output.clone(),
    };
    if let Some(slurm_options) = &options.slurm {
        let exe = std::env::current_exe().context("cannot find the stentkit executable")?;
        let absolute = std::path::absolute(&dir.dir)
            .with_context(|| format!("cannot resolve {}", dir.dir.display()))?;
        slurm::check_script_values(&absolute, &exe, &plan, slurm_options)
            .map_err(|e| BadInput(e.to_string()))?;
    }
    dir.check(&plan).map_err(refused)?;
    let to_run: Vec<usize> = (0..plan.variants.len())
        .filter(|&i| dir.state(&plan.variants[i].id).to_run(options.retry_failed))
        .collect();
    let Some(estimate) = disk::estimate(&plan, &to_run, &signals::stop_requested) else {
        return Err(Interrupted(format!(
            "{} while the variants' designs were read: nothing was written",
            signals::first().unwrap_or("signal")
        ))
        .into());
    };
    let concurrent = match &options.slurm {
        Some(s) => s.max_parallel.unwrap_or(to_run.len()),
        None => workers(&options),
    };
    let free = super::disk::check_sweep_space(&plan, &dir.dir, &estimate, concurrent)?;
    eprintln!(
        "disk: about {} for {} variants to run{}",
        human_bytes(super::disk::sweep_bytes(&estimate, concurrent) as Real),
        estimate.variants,
        free.map_or_else(String::new, |f| format!(
            ", {} free",
            human_bytes(f as Real)
        ))
    );
    if let Prepared::Stopped { prepared } = dir
        .prepare(&plan, &estimate.resolved, &signals::stop_requested)
        .map_err(refused)?
    {
        return Err(Interrupted(format!(
            "{}: the preparation stopped with {prepared} of {} variants written (and {}); the same command continues it",
            signals::first().unwrap_or("signal"),
            plan.variants.len(),
            dir.plan_file().display()
        ))
        .into());
    }
    let states: Vec<VariantState> = plan.variants.iter().map(|v| dir.state(&v.id)).collect();
    let mut todo: Vec<usize> = (0..plan.variants.len())
        .filter(|&i| states[i].to_run(options.retry_failed))
        .collect();
    let failed_earlier = states
        .iter()
        .filter(|s| matches!(s, VariantState::Failed(_)))
        .count();
    eprintln!(
        "sweep of {} → {}: {} variants, {} completed earlier, {} to run{}",
        design.display(),
        dir.dir.display(),
        plan.variants.len(),
        states
            .iter()
            .filter(|s| **s == VariantState::Completed)
            .count(),
        todo.len(),
        if failed_earlier > 0 && !options.retry_failed {
            format!(" ({failed_earlier} refused or failed: --retry-failed reruns the failed runs)")
        } else {
            String::new()
        }
    );
    if let Some(slurm_options) = &options.slurm {
        // Variants queued or running in an earlier job of this sweep are not submitted again.
        let jobs = slurm::read_jobs(&dir);
        if let Some(queued) = slurm::queued(&jobs) {
            todo.retain(|i| !queued.contains_key(i));
        }
        return submit(&dir, &plan, &todo, slurm_options, options.dry_run);
    }
    let interrupted = run_locally(&dir, &plan, &todo, &options)?;
    let collected = collect(&dir, options.at.as_deref())?;
    report(&collected);
    if interrupted {
        return Err(Interrupted(format!(
            "{}: the sweep stopped; finished variants are kept and the same command continues it",
            signals::first().unwrap_or("signal")
        ))
        .into());
    }
    let failed = collected
        .rows
        .iter()
        .filter(|r| matches!(r.state, VariantState::Failed(_)))
        .count();
    anyhow::ensure!(
        failed == 0,
        "{failed} of {} variants failed (their rows in {} say why)",
        collected.rows.len(),
        collected.csv.display()
    );
    Ok(())
}

/// One running worker: a thread running one variant.
struct Worker<'scope> {
    index: usize,
    thread: std::thread::ScopedJoinHandle<'scope, ()>,
    started: Instant,
}

/// A sweep error as the command's: a refused folder or plan is bad input (exit status 2), an I/O error is not.
fn refused(e: crate::sweep::SweepError) -> anyhow::Error {
    match e {
        crate::sweep::SweepError::Io { .. } => anyhow::Error::from(e),
        e => BadInput(e.to_string()).into(),
    }
}

/// Local workers: `--jobs`, or the cores over the threads per run (at least one).
fn workers(options: &SweepOptions) -> usize {
    let threads = options.threads_per_run.max(1);
    let cores = std::thread::available_parallelism().map_or(1, usize::from);
    options.jobs.unwrap_or(cores / threads).max(1)
}

/// Runs the variants `todo` with the options' workers; returns whether a signal stopped the sweep.
fn run_locally(
    dir: &SweepDir,
    plan: &Plan,
    todo: &[usize],
    options: &SweepOptions,
) -> anyhow::Result<bool> {
    let threads = options.threads_per_run.max(1);
    let jobs = workers(options);
    if todo.is_empty() {
        return Ok(false);
    }
    eprintln!("{jobs} workers, {threads} thread(s) per run");
    let bar = ProgressBar::with_draw_target(Some(todo.len() as u64), ProgressDrawTarget::stderr());
    bar.set_style(
        ProgressStyle::with_template(
            "{elapsed_precise} [{bar:30}] {pos}/{len} ETA {eta:>4}  {msg}",
        )
        .expect("valid progress template")
        .progress_chars("=> "),
    );
    // What the running variants are told when the sweep is signalled: one request, as the one SIGTERM each
    // worker process was sent (a second would make a run skip its final snapshot).
    let variants = Interrupt::new();
    std::thread::scope(|scope| {
        let (mut queue, mut running) = (todo.iter().copied(), Vec::<Worker<'_>>::new());
        let (mut done, mut failed) = (0usize, 0usize);
        loop {
            let stopping = signals::stop_requested();
            while !stopping && running.len() < jobs {
                let Some(index) = queue.next() else {
                    break;
                };
                let variants = &variants;
                let retry_failed = options.retry_failed;
                running.push(Worker {
                    index,
                    thread: scope.spawn(move || {
                        run_variant(dir, plan, index, threads, retry_failed, variants)
                    }),
                    started: Instant::now(),
                });
            }
            if stopping && !variants.requested() {
                variants.request("SIGTERM");
                // What each worker process printed into its log on the SIGTERM it was sent.
                for w in &running {
                    let log = dir.log(&plan.variants[w.index].id);
                    let line = format!("\nSIGTERM: {}\n", signals::RUN.first);
                    let _ = crate::io::no_follow::open(
                        &log,
                        std::fs::OpenOptions::new().create(true).append(true),
                    )
                    .and_then(|mut f| std::io::Write::write_all(&mut f, line.as_bytes()));
                }
            }
            let mut k = 0;
            while k < running.len() {
                if !running[k].thread.is_finished() {
                    k += 1;
                    continue;
                }
                let w = running.swap_remove(k);
                if let Err(panic) = w.thread.join() {
                    std::panic::resume_unwind(panic);
                }
                let id = &plan.variants[w.index].id;
                let state = dir.state(id);
                match &state {
                    VariantState::Completed => done += 1,
                    VariantState::Failed(_) => failed += 1,
                    _ => {}
                }
                bar.inc(1);
                bar.suspend(|| {
                    eprintln!(
                        "{id} [{}] {} in {:.1} s",
                        plan.label(w.index),
                        state.name(),
                        w.started.elapsed().as_secs_f64()
                    );
                });
            }
            bar.set_message(format!(
                "{done} done, {failed} failed, {} running",
                running.len()
            ));
            if running.is_empty() && (stopping || queue.len() == 0) {
                break;
            }
            std::thread::sleep(Duration::from_millis(100));
        }
    });
    bar.finish_and_clear();
    Ok(signals::stop_requested())
}

/// Runs variant `index` in process, on a rayon pool of `threads` threads, its messages appended to the
/// variant's log (what `stentkit sweep task DIR INDEX` with `RAYON_NUM_THREADS=threads` wrote there, its error
/// line included).
fn run_variant(
    dir: &SweepDir,
    plan: &Plan,
    index: usize,
    threads: usize,
    retry_failed: bool,
    interrupt: &Interrupt,
) {
    let log_path = dir.log(&plan.variants[index].id);
    let log = match crate::io::no_follow::open(
        &log_path,
        std::fs::OpenOptions::new().create(true).append(true),
    ) {
        Ok(log) => log,
        Err(e) => {
            eprintln!("warning: cannot open {}: {e}", log_path.display());
            return;
        }
    };
    let mut console = super::run::Terminal::new(true, false, super::run::Out::log(log));
    // The command line a worker process had, as its runs record it.
    let command = std::env::current_exe()
        .map(|exe| {
            let mut args = vec![exe.display().to_string(), "sweep".into(), "task".into()];
            args.push(dir.dir.display().to_string());
            args.push(index.to_string());
            if retry_failed {
                args.push("--retry-failed".into());
            }
            super::run::quoted_command_line(args)
        })
        .unwrap_or_else(|_| super::run::command_line());
    let started = (Instant::now(), command);
    let result = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(anyhow::Error::from)
        .and_then(|pool| {
            pool.install(|| {
                task_with(
                    &dir.dir,
                    index,
                    retry_failed,
                    started,
                    &mut console,
                    interrupt,
                )
            })
        });
    if let Err(e) = result {
        console.say(&format!("error: {}", super::error_text(&e)));
    }
}

/// Writes the batch script of `todo` and submits it (or only writes it with `dry_run`).
fn submit(
    dir: &SweepDir,
    plan: &Plan,
    todo: &[usize],
    options: &SlurmOptions,
    dry_run: bool,
) -> anyhow::Result<()> {
    if todo.is_empty() {
        eprintln!("nothing to submit: every variant is completed, failed or queued");
        return Ok(());
    }
    let absolute = slurm::absolute(&dir.dir)?;
    let exe = std::env::current_exe().context("cannot find the stentkit executable")?;
    let text = slurm::sbatch_text(&absolute, &exe, plan, todo, options)
        .map_err(|e| BadInput(e.to_string()))?;
    let script = dir.dir.join("sweep.sbatch");
    crate::io::no_follow::write(&script, text.as_bytes())
        .with_context(|| format!("cannot write {}", script.display()))?;
    if dry_run {
        println!(
            "wrote {} ({} tasks); submit it with: sbatch {}",
            script.display(),
            todo.len(),
            script.display()
        );
        return Ok(());
    }
    let id = slurm::submit(&script).map_err(anyhow::Error::msg)?;
    slurm::record_job(
        dir,
        Job {
            id: id.clone(),
            tasks: todo.to_vec(),
        },
    )?;
    println!(
        "submitted job {id}: array {} ({} tasks); `stentkit sweep status {}` follows it, `stentkit sweep collect {}` tabulates",
        slurm::array_ranges(todo),
        todo.len(),
        dir.dir.display(),
        dir.dir.display()
    );
    Ok(())
}

/// Runs variant `index` of the sweep in `dir` (what a worker or an array task does): nothing when completed;
/// a failed one only with `retry_failed`; an unfinished one continues from its checkpoint; otherwise a fresh
/// run (replacing the files of an earlier attempt only).
///
/// # Errors
/// [`BadInput`] for an unknown index, a refused design or a failed variant without `retry_failed`; the run's
/// own errors.
pub(crate) fn task(dir: &Path, index: usize, retry_failed: bool) -> anyhow::Result<()> {
    signals::install();
    let mut console = super::run::Terminal::new(true, false, super::run::Out::default());
    let started = (Instant::now(), super::run::command_line());
    task_with(
        dir,
        index,
        retry_failed,
        started,
        &mut console,
        &signals::INTERRUPT,
    )
}

/// [`task`] started at `started.0` by the command line `started.1`, its messages going to `console`, stopped
/// by `interrupt` (a local worker's, in process).
///
/// # Errors
/// As [`task`].
fn task_with(
    dir: &Path,
    index: usize,
    retry_failed: bool,
    started: (Instant, String),
    console: &mut dyn Console,
    interrupt: &Interrupt,
) -> anyhow::Result<()> {
    let sweep = SweepDir {
        dir: dir.to_path_buf(),
    };
    let plan = sweep.read_plan().map_err(|e| BadInput(e.to_string()))?;
    let id = plan
        .variants
        .get(index)
        .map(|v| v.id.clone())
        .ok_or_else(|| {
            BadInput(format!(
                "{}: no variant {index} (the sweep has {})",
                dir.display(),
                plan.variants.len()
            ))
        })?;
    console.say(&format!(
        "stentkit sweep task {index}: {id} [{}]",
        plan.label(index)
    ));
    if sweep.error(&id).exists() {
        return Err(BadInput(format!(
            "{id}: its design was refused ({})",
            sweep.error(&id).display()
        ))
        .into());
    }
    let state = sweep.state(&id);
    let run_dir = sweep.run(&id);
    let checkpoint = run_dir.join(crate::io::checkpoint::FILE_NAME).exists();
    let (resume, force) = match &state {
        VariantState::Completed => {
            console.say(&format!("{id}: completed earlier"));
            return Ok(());
        }
        VariantState::Failed(why) if !retry_failed => {
            return Err(BadInput(format!(
                "{id} failed earlier ({why}); rerun it with --retry-failed"
            ))
            .into());
        }
        VariantState::Unfinished(_) if checkpoint && plan.bench.is_none() => (true, false),
        _ => (false, run_dir.exists()),
    };
    let _ = std::fs::remove_file(sweep.task_error(&id));
    let result = match plan.bench {
        Some(test) => super::bench::bench_into(
            test,
            &sweep.design(&id),
            &run_dir,
            force,
            started,
            console,
            interrupt,
        )
        .map(|(report, lines)| {
            console.say(&report);
            for l in lines {
                console.say(&l);
            }
        }),
        None => {
            let options = super::run::RunOptions {
                output: (!resume).then(|| run_dir.clone()),
                force,
                quiet: true,
                verbose: false,
                resume: resume.then(|| run_dir.clone()),
                checkpoint_every: 60.0,
                time_tolerance: None,
                sets: Vec::new(),
            };
            super::run::run_with(&sweep.design(&id), options, started, console, interrupt)
                .map(|completed| console.say(&completed.report))
        }
    };
    if let Err(e) = &result
        && !run_dir.join("summary.json").exists()
    {
        // Refused before the run folder had a summary: the state must say so.
        let _ =
            crate::io::no_follow::write(&sweep.task_error(&id), super::error_text(e).as_bytes());
    }
    result
}

/// `stentkit sweep collect DIR`.
///
/// # Errors
/// When DIR holds no sweep or the table cannot be written.
pub(crate) fn collect_command(dir: &Path, at: Option<Vec<Real>>) -> anyhow::Result<()> {
    let sweep = SweepDir {
        dir: dir.to_path_buf(),
    };
    let collected = collect(&sweep, at.as_deref()).map_err(refused)?;
    report(&collected);
    Ok(())
}

/// Prints what a collection holds.
fn report(collected: &Collected) {
    let count = |name: &str| {
        collected
            .rows
            .iter()
            .filter(|r| r.state.name() == name)
            .count()
    };
    println!(
        "{} variants: {} completed, {} failed, {} pending, {} unfinished → {} ({} charts)",
        collected.rows.len(),
        count("completed"),
        count("failed"),
        count("pending"),
        collected.rows.len() - count("completed") - count("failed") - count("pending"),
        collected.csv.display(),
        collected.charts.len()
    );
}

/// `stentkit sweep status DIR`: each variant's state, with the scheduler's for the tasks Slurm still lists.
///
/// # Errors
/// When DIR holds no sweep.
pub(crate) fn status(dir: &Path) -> anyhow::Result<()> {
    let sweep = SweepDir {
        dir: dir.to_path_buf(),
    };
    let plan = sweep.read_plan().map_err(|e| BadInput(e.to_string()))?;
    let jobs = slurm::read_jobs(&sweep);
    let queued = slurm::queued(&jobs);
    if !jobs.is_empty() {
        let ids: Vec<&str> = jobs.iter().map(|j| j.id.as_str()).collect();
        match &queued {
            Some(q) => println!(
                "Slurm jobs {}: {} tasks queued or running",
                ids.join(", "),
                q.len()
            ),
            None => println!(
                "Slurm jobs {}: squeue is not available here; states from the run folders",
                ids.join(", ")
            ),
        }
    }
    let mut counts = std::collections::BTreeMap::<String, usize>::new();
    for (i, v) in plan.variants.iter().enumerate() {
        let state = sweep.state(&v.id);
        let name = match queued.as_ref().and_then(|q| q.get(&i)) {
            Some(s) => format!("slurm:{}", s.to_lowercase()),
            None => state.name().to_string(),
        };
        let why = match &state {
            VariantState::Failed(why) => format!("  {}", why.lines().next().unwrap_or("")),
            _ => String::new(),
        };
        println!("{}  {name:<16} {}{why}", v.id, plan.label(i));
        *counts.entry(name).or_default() += 1;
    }
    println!(
        "{}",
        counts
            .iter()
            .map(|(k, n)| format!("{n} {k}"))
            .collect::<Vec<_>>()
            .join(", ")
    );
    Ok(())
}
