//! What the benchmarks (`examples/*_bench.rs`) need of the internals; not part of the API.
