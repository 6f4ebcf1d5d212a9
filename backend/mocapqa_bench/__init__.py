"""The benchmarks of mocapqa: figures on the corpus, and their ``mocapqa bench`` commands
(:mod:`mocapqa_bench.cli`). The product (:mod:`mocapqa`) never imports this package."""
