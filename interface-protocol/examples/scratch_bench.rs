// Scratch (not part of the tree): prints the IPC bench.
fn main() {
    let b = interface_protocol::bench::run(&format!("bench{}", std::process::id()), &interface_protocol::bench::DEFAULT_SIZES).unwrap();
    println!("cores {}", b.cores);
    for r in b.rows { println!("{:12} n={:>8} repeats={:>5} median={:>12.1} us min={:>12.1} us", r.transport, r.nodes, r.repeats, r.round_trip_us_median, r.round_trip_us_min); }
}
