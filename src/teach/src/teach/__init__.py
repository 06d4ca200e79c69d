"""Teach by hand: programs of hand-guided motions (see the package README)."""
