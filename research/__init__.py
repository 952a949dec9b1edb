"""One-off probes that chose nothing (research/README.md), each run from the repository root as
`python -m research.NAME [--help]`. They share benchmarks.common and research.common; no probe imports another."""
