"""Dataset building: clip discovery, captions, shape texts, the builder."""
