"""Monte-Carlo sweeps: variants of a scenario drawn from a distribution, ridden by several
controllers in parallel (``ridempc sweep``), and the statistics and report they give."""
