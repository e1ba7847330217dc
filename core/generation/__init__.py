"""Text -> body shape + motion: prompt checks and the generation pipeline."""
