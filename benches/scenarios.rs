//! Criterion benches of the report's scenarios (registered from
//! `crates/tcb-bench/Cargo.toml`): one pass of each implementation.
//!
//! ```text
//! cargo bench -p tcb-bench --bench scenarios [-- wide]
//! ```

use criterion::{Criterion, criterion_group, criterion_main};
use tcb_bench::scenarios;

fn bench(c: &mut Criterion) {
    let all = scenarios::all(&scenarios::default_bvh()).expect("the bundled CMU clip loads");
    for s in &all {
        let mut g = c.benchmark_group(s.name.as_str());
        g.sample_size(20);
        let mut run = s.baseline_pass(s.times.clone(), s.phases.clone());
        g.bench_function("baseline", |b| b.iter(&mut run));
        let mut run = s.runtime_pass();
        g.bench_function("runtime", |b| b.iter(&mut run));
        if s.parallel {
            let mut run = s.parallel_pass();
            g.bench_function("runtime_parallel", |b| b.iter(&mut run));
        }
        if let Some(mut run) = s.peer_pass(s.times.clone()) {
            g.bench_function("splines", |b| b.iter(&mut run));
        }
        if s.read_limit {
            let mut run = s.read_pass();
            g.bench_function("read_limit", |b| b.iter(&mut run));
        }
        g.finish();
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
