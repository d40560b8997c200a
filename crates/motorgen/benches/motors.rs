//! Motors per second on one core at normal detail: build only, build plus export of every format
//! (whole motor and per part) into memory, and the full write to disk with its atomic renames.

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use motorgen::export::{write_glb, write_motor, write_obj, write_ply, write_stl};
use motorgen::{Detail, Format, Motor, ParamSpace, Part, build};

fn export_all(m: &Motor, buf: &mut Vec<u8>) {
    let whole: Vec<&Part> = m.parts.iter().collect();
    let groups = std::iter::once(whole).chain(m.parts.iter().map(|p| vec![p]));
    for parts in groups {
        buf.clear();
        write_obj(buf, &parts, Some("materials.mtl")).unwrap();
        write_stl(buf, &parts).unwrap();
        write_ply(buf, &parts).unwrap();
        write_glb(buf, &parts).unwrap();
        black_box(&buf);
    }
}

fn motors(c: &mut Criterion) {
    let space = ParamSpace::addon();
    let mut g = c.benchmark_group("motors");
    g.throughput(Throughput::Elements(1));
    let mut seed = 0u64;
    let mut next = || {
        seed += 1;
        space.sample(seed).unwrap()
    };
    g.bench_function("build_normal", |b| {
        b.iter(|| black_box(build(&next(), Detail::Normal)))
    });
    g.bench_function("build_coarse", |b| {
        b.iter(|| black_box(build(&next(), Detail::Coarse)))
    });
    g.bench_function("build_fine", |b| {
        b.iter(|| black_box(build(&next(), Detail::Fine)))
    });
    let mut buf = Vec::with_capacity(1 << 24);
    g.bench_function("build_normal_export_all_formats_to_memory", |b| {
        b.iter(|| export_all(&build(&next(), Detail::Normal), &mut buf))
    });
    // a fresh folder per motor, as in a dataset run (renaming over existing files on ext4
    // forces a flush per file and costs several times more)
    let dir = tempfile::tempdir().unwrap();
    let mut n = 0u64;
    g.bench_function("build_normal_write_obj_ply_to_disk", |b| {
        b.iter(|| {
            n += 1;
            let out = dir.path().join(n.to_string());
            write_motor(
                &build(&next(), Detail::Normal),
                &out,
                &[Format::Obj, Format::Ply],
                true,
            )
            .unwrap()
        })
    });
    g.finish();
}

criterion_group!(benches, motors);
criterion_main!(benches);
