"""Training and evaluation of policies (filled in by later issues)."""
