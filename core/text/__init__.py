"""Plain-text understanding shared by the dataset builder and the body fit (leaf modules: they
import nothing of the project but ``errors`` and ``constants``)."""
