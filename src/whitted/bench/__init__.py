"""``whitted bench``: the standard benchmark scenes (``benchmarks/``), timed stage by stage,
optionally beside POV-Ray, and the seeds' thread-count and image-size studies."""
