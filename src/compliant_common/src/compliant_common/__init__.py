"""Runtime helpers shared by the stack's nodes (see the package README)."""
