"""Text search over a folder of motions with the TMA."""
