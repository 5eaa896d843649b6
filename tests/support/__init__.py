"""Helpers shared by the test folders (imported as ``support.<module>``; pyproject.toml puts tests/
on the path): the repository paths, the generic element checks, the assembled core simulation,
static equilibrium, the fuzzing harness and the spatial models."""
