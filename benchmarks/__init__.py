"""Scripts that print tables (run by hand, never tests), each run from the repository root as
`python -m benchmarks.NAME [--help]`. What they share lives in `benchmarks.common`; no script imports another.
One-off probes that chose nothing live in research/ (research/README.md)."""
