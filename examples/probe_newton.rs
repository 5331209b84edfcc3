use std::ops::ControlFlow;
use stentkit::solver::{Observer, Simulation, StepReport};
struct P(usize);
impl Observer for P {
    fn step(&mut self, _: &Simulation<'_>, r: &StepReport) -> ControlFlow<()> {
        if r.step % self.0 == 0 {
            println!(
                "{} t={:.4} it={} f={} res={:.1e} inc={:.1e}",
                r.step,
                r.time,
                r.newton.iterations,
                r.newton.factorisations,
                V(&r.newton.residuals),
                V(&r.newton.increments)
            );
        }
        ControlFlow::Continue(())
    }
}
fn main() -> anyhow::Result<()> {
    let path = std::env::args().nth(1).unwrap();
    let every: usize = std::env::args().nth(2).unwrap().parse()?;
    let end: Option<f64> = std::env::args().nth(3).map(|s| s.parse()).transpose()?;
    let text = std::fs::read_to_string(&path)?;
    let overrides = stentkit::io::design::DesignOverrides {
        end_time: end,
        ..Default::default()
    };
    let design =
        stentkit::io::design::parse_design_with(&text, std::path::Path::new(&path), &overrides)?;
    let mut sim = Simulation::new(&design.model)?;
    let s = sim.run(&mut P(every))?;
    println!("{s:?}\n{:?}", sim.timing());
    Ok(())
}
struct V<'a>(&'a [f64]);
impl std::fmt::LowerExp for V<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        for x in self.0 {
            write!(f, "{x:.1e} ")?;
        }
        Ok(())
    }
}
