"""Neural models: the SA-VAE (FSQ, encoder/decoder, shape injection, losses); T5 + [BETA] head, TMA."""
