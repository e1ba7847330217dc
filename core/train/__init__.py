"""Training loops (``train_KIND.py`` with ``train_KIND(...)``), checkpoints, datasets, DDP helpers."""
