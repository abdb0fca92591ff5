"""Scripted visual-homing controllers (filled in by the evaluation-harness issue)."""
