//! Coverage-only speed of the four traversals (`cargo bench --bench traversal`).
//!
//! Each benchmark rasterizes a whole workload into a 1-bit mask; throughput is counted
//! in covered pixels, so criterion prints Melem/s = covered Mpixel/s, and the time per
//! iteration divided by the triangle count printed below gives ns per triangle.

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use std::hint::black_box;
use termrast::raster::{BitMask, Setup, Target, Traversal};
use termrast::workload::{Tri2, sliver_fan, tiling, tiny_triangles};

fn covered(tris: &[Tri2], target: Target) -> u64 {
    let mut m = BitMask::new(target.width, target.height);
    let mut n = 0;
    for t in tris {
        if let Ok(s) = Setup::new(*t, target) {
            let before = m.count();
            Traversal::Scalar.run(&s, &mut m);
            n += m.count() - before;
            m.clear();
        }
    }
    n
}

fn bench(c: &mut Criterion) {
    let target = Target::new(1920, 1080);
    let workloads: [(&str, Vec<Tri2>); 3] = [
        ("tiny-10k", tiny_triangles(10_000, 1920, 1080, 1)),
        ("large-100", tiling(10, 5, 1920, 1080, 2)),
        ("sliver-fan-2000", sliver_fan(2000, 1920, 1080, 3)),
    ];
    for (name, tris) in &workloads {
        let px = covered(tris, target);
        eprintln!(
            "workload {name}: {} triangles, {px} covered pixels",
            tris.len()
        );
        let mut g = c.benchmark_group(*name);
        g.throughput(Throughput::Elements(px));
        let mut mask = BitMask::new(target.width, target.height);
        for t in Traversal::ALL {
            g.bench_function(BenchmarkId::from_parameter(t.name()), |b| {
                b.iter(|| {
                    mask.clear();
                    for tri in tris {
                        if let Ok(s) = Setup::new(*tri, target) {
                            t.run(&s, &mut mask);
                        }
                    }
                    black_box(&mask);
                });
            });
        }
        g.finish();
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20).measurement_time(std::time::Duration::from_secs(3));
    targets = bench
}
criterion_main!(benches);
