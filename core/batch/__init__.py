"""Batches of prompts that outgrow one process (docs/batches.md): the items of a prompts file
(``items.py``, a shard of them ``shard.py``), one line per item in ``manifest.jsonl``
(``manifest.py``, its files ``outputs.py``, the model's identity ``model_identity.py``), the item
task of ``generate --prompts`` (``generate_item.py``), where items run (``engines.py``: in this
process, ``--jobs N`` worker processes, a Dask cluster), the loop that resumes and records
(``runner.py``), its progress (``progress.py``) and the join of shards' manifests (``merge.py``)."""
