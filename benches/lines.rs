//! Midpoint line speed (`cargo bench --bench lines`): short (≤ 8 px) and long
//! (1000 px) lines, trace off and on. Throughput is in lines; pixels per second are
//! lines per second times the mean length printed below.

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use std::hint::black_box;
use termrast::raster::line::{Line, NoTrace, Step};
use termrast::workload::Rng;

fn lines(n: usize, len: f64, seed: u64) -> Vec<Line> {
    let mut r = Rng::new(seed);
    (0..n)
        .map(|_| {
            let a = (r.range(0.0, 1000.0) as i64, r.range(0.0, 1000.0) as i64);
            let t = r.range(0.0, std::f64::consts::TAU);
            let b = (
                a.0 + (len * t.cos()).round() as i64,
                a.1 + (len * t.sin()).round() as i64,
            );
            Line::new(a, b).expect("in range")
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    for (name, set) in [
        ("short", lines(10_000, 7.0, 1)),
        ("long", lines(1_000, 1000.0, 2)),
    ] {
        let px: i64 = set.iter().map(Line::len).sum();
        eprintln!("{name}: {} lines, {} pixels", set.len(), px);
        let mut g = c.benchmark_group(format!("lines-{name}"));
        g.throughput(Throughput::Elements(set.len() as u64));
        g.bench_function(BenchmarkId::from_parameter("trace-off"), |b| {
            b.iter(|| {
                let mut sum = 0i64;
                for l in &set {
                    l.draw(|x, y| sum += x ^ y, &mut NoTrace);
                }
                black_box(sum)
            });
        });
        let mut steps: Vec<Step> = Vec::with_capacity(2048);
        g.bench_function(BenchmarkId::from_parameter("trace-on"), |b| {
            b.iter(|| {
                let mut sum = 0i64;
                for l in &set {
                    steps.clear();
                    l.draw(|x, y| sum += x ^ y, &mut steps);
                }
                black_box((sum, steps.len()))
            });
        });
        g.finish();
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20).measurement_time(std::time::Duration::from_secs(2));
    targets = bench
}
criterion_main!(benches);
