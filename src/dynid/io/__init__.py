"""Input/output: atomic file writing and JSON results."""

from .files import atomic_write_bytes, atomic_write_text, write_json

__all__ = ["atomic_write_bytes", "atomic_write_text", "write_json"]
