//! Stepping as an API and checkpoints (issue 13 item 4): a simulation restored from a checkpoint continues
//! **bit for bit** as the uninterrupted one — the same Newton residuals, increments and factorisations in every
//! step and the same final state — whether the checkpoint is restored into a new simulation or into the one
//! it came from after that went on; and a checkpoint of another model is refused.
//!
//! Source: the contract itself (`solver::simulation::checkpoint`): the restored simulation must reuse the
//! same factorisation, release ramps, gauge constraints and material history as the original, so any missing
//! piece shows as a differing residual sequence. Designs: the straight stent with two crowns to t = 2 s in steps
//! of 0.01 s (Maxwell/WLF, 15 branches; the programme's release at 1.75 s captures reaction ramps and switches on
//! gauge constraints with Lagrange multipliers) and the 45° bend (elastic) in steps of 0.5, whose first step is
//! cut twice (the step size grows back over the next), also with the extrapolated start of each step (which
//! reads the last step's increment), and the stent with error-controlled steps (rejected attempts, the
//! controller's memory). Exact comparisons: no tolerance.

use crate::common::fixtures;
use std::ops::ControlFlow;
use stentkit::model::{Model, SolverSettings, TimeSettings};
use stentkit::solver::{CheckpointError, Observer, Simulation, StepOutcome, StepReport};

/// Steps a simulation to the end, returning its reports.
fn finish(sim: &mut Simulation<'_>) -> Vec<StepReport> {
    let mut reports = Vec::new();
    while let Some(report) = sim.step().unwrap_or_else(|e| panic!("{e}")) {
        reports.push(report);
    }
    reports
}

/// The straight stent with two crowns, to t = 2 s in steps of 0.01 s (release at 1.75 s: step 175).
fn small_stent() -> Model {
    fixtures::straight_stent().crowns(2).time(2.0, 0.01).model()
}

/// The same stent with error-controlled steps (tolerance 1e-3 from a first step of 0.01): the step-size
/// controller's memory, rejected attempts (which keep their factorisation) and the error estimates (which may
/// factorise) must continue exactly too.
fn small_stent_adaptive() -> Model {
    fixtures::straight_stent()
        .crowns(2)
        .time(2.0, 0.01)
        .set("time.tolerance", "1.0e-3")
        .model()
}

/// The 45° bend in steps of 0.5: the first is cut twice, so the step size is below the nominal one for a step.
fn cut_bend() -> Model {
    fixtures::bend45().time(1.0, 0.5).model()
}

#[test]
fn a_restored_simulation_continues_bit_for_bit() {
    // The bend again with the extrapolated start (`solver.extrapolate`), which reads the last step's increment.
    let bend = cut_bend();
    let extrapolated = bend
        .clone()
        .with_solver(SolverSettings {
            extrapolate: true,
            ..bend.solver().clone()
        })
        .and_then(|m| m.with_name("bend45_extrapolated"))
        .expect("valid settings and name");
    for model in [
        small_stent(),
        small_stent_adaptive(),
        cut_bend(),
        extrapolated,
    ] {
        let mut full = Simulation::new(&model).expect("simulation");
        let reports = finish(&mut full);
        assert!(full.is_finished(), "{}", model.name());
        if model.time().tolerance.is_some() {
            let rejected: usize = reports.iter().map(|r| r.rejected).sum();
            println!(
                "{}: {} steps, {rejected} rejected",
                model.name(),
                reports.len()
            );
            assert!(rejected > 0, "the adaptive run rejects some steps");
        }
        let n = reports.len();
        // At the start, early, around the release (the stent's at 1.75 s, step 175 of 200), near the end.
        let mut at_steps = vec![0, 1, n / 3, n * 7 / 8 - 1, n * 7 / 8 + 1, n - 1];
        at_steps.retain(|&k| k < n);
        at_steps.dedup();
        for at in at_steps {
            let mut first = Simulation::new(&model).expect("simulation");
            for _ in 0..at {
                first.step().expect("steps").expect("not at the end");
            }
            let checkpoint = first.checkpoint();
            assert_eq!(checkpoint.snapshot.clock.step, at);
            // The original goes on (its factorisation, state and history change), then is rewound.
            let ahead = finish(&mut first);
            assert_eq!(
                ahead,
                reports[at..],
                "{} from step {at}: uninterrupted",
                model.name()
            );
            first.restore(&checkpoint).expect("same model");
            let rewound = finish(&mut first);
            assert_eq!(
                rewound,
                reports[at..],
                "{} from step {at}: rewound",
                model.name()
            );
            assert!(first.state() == full.state());
            // A new simulation of the same model.
            let mut second = Simulation::new(&model).expect("simulation");
            second.restore(&checkpoint).expect("same model");
            assert_eq!(second.time(), checkpoint.snapshot.clock.time);
            assert_eq!(second.checkpoint(), checkpoint, "restoring changes nothing");
            let resumed = finish(&mut second);
            assert_eq!(
                resumed,
                reports[at..],
                "{} from step {at}: new simulation",
                model.name()
            );
            assert!(
                second.state() == full.state(),
                "{} from step {at}",
                model.name()
            );
            assert_eq!(second.notices(), full.notices());
            println!(
                "{}: restored at step {at} (t = {}, factorisation {}), {} more steps bit for bit",
                model.name(),
                checkpoint.snapshot.clock.time,
                if checkpoint.tangent.is_some() {
                    "rebuilt"
                } else {
                    "none"
                },
                resumed.len()
            );
        }
    }
}

#[test]
fn a_checkpoint_of_another_model_is_refused() {
    let stent = small_stent();
    let bend = fixtures::bend45().model();
    let checkpoint = Simulation::new(&bend).expect("simulation").checkpoint();
    let mut sim = Simulation::new(&stent).expect("simulation");
    let error = sim.restore(&checkpoint).expect_err("another model");
    assert!(
        matches!(error, CheckpointError::ModelMismatch { .. }),
        "{error}"
    );
    // The same geometry with another load is another model too.
    let heavier = bend
        .clone()
        .with_time(TimeSettings {
            end: 2.0 * bend.time().end,
            ..bend.time().clone()
        })
        .expect("a longer run");
    let mut sim = Simulation::new(&heavier).expect("simulation");
    assert!(matches!(
        sim.restore(&checkpoint),
        Err(CheckpointError::ModelMismatch { .. })
    ));
}

/// Interrupts at its `at`-th poll ([`Observer::interrupted`] is asked before every attempt and every Newton
/// iteration).
struct InterruptAt {
    polls: std::cell::Cell<usize>,
    at: usize,
}

impl Observer for InterruptAt {
    fn step(&mut self, _: &Simulation<'_>, _: &StepReport) -> ControlFlow<()> {
        ControlFlow::Continue(())
    }

    fn interrupted(&self) -> bool {
        self.polls.set(self.polls.get() + 1);
        self.polls.get() == self.at
    }
}

/// An interruption within a step abandons it (rolled back); the simulation then continues — in itself, or
/// restored from a checkpoint taken right after the interruption — bit for bit as the uninterrupted run: the
/// factorisation the abandoned attempt started with is kept, or made again when the attempt replaced it.
/// Interruptions at many points of the stent's run (before attempts, within Newton, after factorisations,
/// around the release).
#[test]
fn an_interrupted_simulation_continues_bit_for_bit() {
    let model = small_stent();
    let mut full = Simulation::new(&model).expect("simulation");
    let reports = finish(&mut full);
    let total_polls: usize = reports
        .iter()
        .map(|r| 1 + r.newton.iterations + r.cuts)
        .sum();
    let mut kept = 0;
    for k in 1..=12 {
        let at = k * total_polls / 13 + k;
        let mut sim = Simulation::new(&model).expect("simulation");
        let mut observer = InterruptAt {
            polls: std::cell::Cell::new(0),
            at,
        };
        let mut before = Vec::new();
        loop {
            match sim.step_with(&mut observer).expect("steps") {
                StepOutcome::Stepped(report) => before.push(*report),
                StepOutcome::Interrupted => break,
                StepOutcome::Finished => panic!("not interrupted (poll {at})"),
            }
        }
        let n = before.len();
        assert_eq!(before, reports[..n]);
        let checkpoint = sim.checkpoint();
        kept += usize::from(checkpoint.tangent.is_some());
        let mut restored = Simulation::new(&model).expect("simulation");
        restored.restore(&checkpoint).expect("same model");
        let continued = finish(&mut sim);
        assert_eq!(
            continued,
            reports[n..],
            "interrupted at poll {at} (step {n}): continued"
        );
        assert!(sim.state() == full.state());
        let resumed = finish(&mut restored);
        assert_eq!(
            resumed,
            reports[n..],
            "interrupted at poll {at} (step {n}): restored"
        );
        assert!(restored.state() == full.state());
    }
    println!(
        "12 interruptions, {kept} with a factorisation to keep or make again, all continued bit for bit"
    );
}

/// An abandoned attempt puts back everything a step changes: interrupted within the first step of the stent's
/// release snap (step 176, 1.75 → 1.76 s: the captured reactions start to fall, Newton iterates the rods and the
/// gauge constraints' multipliers), the simulation's [`stentkit::solver::StepSnapshot`] — clock, configuration
/// with its multipliers, last increment, ramps, gauge activity, arc-length and terms' states — equals the one
/// before the step. The step taken afterwards changes the configuration, multipliers included, so the
/// comparison is not of parts the step leaves alone.
/// Source: the roll-back's contract (`solver::simulation::snapshot`); exact comparison, no tolerance.
#[test]
fn an_abandoned_attempt_puts_back_everything_a_step_changes() {
    let model = small_stent();
    let mut sim = Simulation::new(&model).expect("simulation");
    for _ in 0..175 {
        sim.step().expect("steps").expect("not at the end");
    }
    let before = sim.checkpoint();
    assert_eq!(before.snapshot.clock.time, 1.75);
    assert!(before.gauge.is_some() && before.snapshot.releases.gauge_active);
    let ramps = |c: &stentkit::solver::Checkpoint| {
        c.snapshot.releases.ramps.iter().flatten().flatten().count()
    };
    assert!(ramps(&before) > 0, "the release reactions are captured");
    // Poll 1 is before the attempt; polls 2 and 3 come before Newton iterations within it.
    for at in [2, 3] {
        let mut observer = InterruptAt {
            polls: std::cell::Cell::new(0),
            at,
        };
        let outcome = sim.step_with(&mut observer).expect("steps");
        assert_eq!(outcome, StepOutcome::Interrupted, "poll {at}");
        assert_eq!(
            sim.checkpoint().snapshot,
            before.snapshot,
            "interrupted at poll {at}"
        );
    }
    let report = sim.step().expect("steps").expect("not at the end");
    assert!(report.newton.iterations >= 2, "{report:?}");
    let stepped = sim.checkpoint().snapshot.solution;
    assert_ne!(
        stepped.state.control,
        before.snapshot.solution.state.control
    );
    assert_ne!(
        stepped.state.multipliers,
        before.snapshot.solution.state.multipliers
    );
}
