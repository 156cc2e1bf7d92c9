//! Per-node profile of the PR model in tract: the plan primm runs for a batch of this size (the
//! batch fixed when the plan is made, as `PrModel` does) is run through `run_plan_with_eval`,
//! timing every node's evaluation (the method of the `tract` command line's `--profile`), summed
//! per operator type and listed per node; then the same plan without the profiler, and the
//! graph planned for a symbolic batch, for comparison.
//!
//! `cargo bench --bench inference_profile [-- MODEL [BATCH]]` (defaults: models/pr.onnx, 64).
//! Nothing is asserted; the output is for reading (`benches/results/pr_profile.txt`).

use std::collections::HashMap;
use std::time::{Duration, Instant};
use tract_onnx::prelude::*;

/// The plan with the batch fixed to `batch` (as primm's runtime builds it), or symbolic.
fn load(path: &str, batch: Option<usize>) -> TractResult<std::sync::Arc<TypedSimplePlan>> {
    let mut model = tract_onnx::onnx().model_for_path(path)?;
    let b = model.symbols.sym("batch").to_dim();
    model.set_input_fact(0, f32::fact([b.clone(), 5.to_dim(), 5.to_dim()]).into())?;
    model.set_input_fact(1, f32::fact([b, 5.to_dim()]).into())?;
    let mut typed = model.into_typed()?;
    if let Some(n) = batch {
        let sym = typed.symbols.sym("batch");
        let mut subs = HashMap::new();
        subs.insert(sym, (n as i64).to_dim());
        typed = typed.set_symbols(&subs)?;
    }
    typed.into_optimized()?.into_runnable()
}

/// Runs `state` `runs` times on `inputs` and prints the mean time per run and per sample.
fn print_mean_run(
    label: &str,
    state: &mut TypedSimpleState,
    inputs: &TVec<TValue>,
    runs: u32,
    batch: usize,
) -> TractResult<()> {
    let start = Instant::now();
    for _ in 0..runs {
        state.run(inputs.clone())?;
    }
    let mean = start.elapsed() / runs;
    let micros = mean.as_secs_f64() * 1e6;
    println!("{label}: {micros:.1} us per run ({:.2} us/sample)", micros / batch as f64);
    Ok(())
}

fn main() -> TractResult<()> {
    // `cargo bench` passes `--bench`; positional arguments are the model and the batch size.
    let positional: Vec<String> = std::env::args().skip(1).filter(|a| !a.starts_with("--")).collect();
    let path = positional
        .first()
        .cloned()
        .unwrap_or_else(|| concat!(env!("CARGO_MANIFEST_DIR"), "/models/pr.onnx").into());
    let batch: usize = positional.get(1).map(|s| s.parse().expect("a batch size")).unwrap_or(64);
    let plan = load(&path, Some(batch))?;
    let mut state = plan.spawn()?;
    let f = Tensor::zero::<f32>(&[batch, 5, 5])?;
    let v = Tensor::from_shape(&[batch, 5], &vec![1.0f32; batch * 5])?;
    let inputs = tvec!(f.into_tvalue(), v.into_tvalue());
    let mut per_node: HashMap<usize, Duration> = HashMap::new();
    let runs = 200;
    let start = Instant::now();
    for _ in 0..runs {
        state.run_plan_with_eval(inputs.clone(), |turn, node_state, node, input| {
            let t = Instant::now();
            let r = tract_onnx::tract_core::plan::eval(turn, node_state, node, input);
            *per_node.entry(node.id).or_default() += t.elapsed();
            r
        })?;
    }
    let total = start.elapsed() / runs;
    let model = plan.model();
    let mut rows: Vec<(usize, Duration)> = per_node.into_iter().collect();
    rows.sort_by_key(|row| std::cmp::Reverse(row.1));
    let sum: Duration = rows.iter().map(|r| r.1).sum::<Duration>() / runs;
    println!(
        "model {path}, batch {batch}: {} nodes, {:.1} us per run ({:.2} us/sample), nodes sum {:.1} us",
        model.nodes().len(),
        total.as_secs_f64() * 1e6,
        total.as_secs_f64() * 1e6 / batch as f64,
        sum.as_secs_f64() * 1e6
    );
    let mut by_op: HashMap<String, (Duration, usize)> = HashMap::new();
    for (id, d) in &rows {
        let e = by_op.entry(model.node(*id).op().name().to_string()).or_default();
        e.0 += *d / runs;
        e.1 += 1;
    }
    let mut ops: Vec<_> = by_op.into_iter().collect();
    ops.sort_by_key(|op| std::cmp::Reverse(op.1 .0));
    println!("by op type (us per run, count):");
    for (op, (d, n)) in ops.iter().take(15) {
        println!("  {:>8.1}  {:>3}  {}", d.as_secs_f64() * 1e6, n, op);
    }
    print_mean_run("the same plan without the profiler", &mut state, &inputs, runs, batch)?;
    let mut symbolic_state = load(&path, None)?.spawn()?;
    print_mean_run("the same model planned for a symbolic batch", &mut symbolic_state, &inputs, runs, batch)?;
    println!("top nodes (us per run, op, ONNX name, output shape):");
    for (id, d) in rows.iter().take(20) {
        let node = model.node(*id);
        let shape =
            model.outlet_fact(OutletId::new(*id, 0)).map(|f| format!("{:?}", f.shape)).unwrap_or_default();
        println!(
            "  {:>8.1}  {:<28} {:<40} {}",
            (*d / runs).as_secs_f64() * 1e6,
            node.op().name(),
            node.name.chars().take(40).collect::<String>(),
            shape
        );
    }
    Ok(())
}
