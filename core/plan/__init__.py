"""What a prompt asks for, read once: the words (``vocabulary.py``, one table of word classes),
the one reader of them (``reader.py``, ``part_prompts.py``, ``segments.py``), the typed reading of
a segment (``words.py``) and the typed plan of ordered segments (``plan.py``) that the generator
acts on; the plan shown to people (``explain.py``, ``reading.py``) and which request wins where the
words and the animation options cannot both be honoured (``option_conflicts.py``)."""
