"""When the training loops save: a mid-run checkpoint every ``every`` steps, and the final save
(the finished model) when the step count is reached. One definition for the SA-VAE, T5 and TMA
loops, so a resumed or interrupted run behaves the same in each."""
from __future__ import annotations

from . import distributed


def save_if_due(save, step: int, every: int, total: int, dist) -> None:
    """``save()`` (a resumable checkpoint) at every ``every``-th step before the last; all ranks wait."""
    if step % every == 0 and step < total:
        save()
        distributed.barrier(dist)


def finish(save, bar, step: int, total: int, dist, metrics: dict) -> dict:
    """End of a loop (finished or cancelled): close the progress bar, save (``final`` when all
    ``total`` steps ran), wait for all ranks; the last metrics with the step reached."""
    bar.close()
    save(final=step >= total)
    distributed.barrier(dist)
    metrics["step"] = step
    return metrics
