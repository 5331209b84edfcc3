use std::ops::ControlFlow;
use stentkit::io::design::load_design;
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
    let design = load_design(std::path::Path::new(&path))?;
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
