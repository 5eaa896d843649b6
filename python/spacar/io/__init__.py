"""Reading and writing the SPACAR95 input format (manual §5) and its state dump (§5.7)."""
from .reader import parse, read, read_string
from .writer import dump

__all__ = ["parse", "read", "read_string", "dump"]
