"""What a prompt asks for, read once: its ordered segments (``segments.py``), what the word readers
understand of each (``reading.py``), and which request wins where the words and the animation
options cannot both be honoured (``option_conflicts.py``)."""
