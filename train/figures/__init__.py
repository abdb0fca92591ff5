"""Reproducible figure and table scripts of the method pages (``python -m
homing_train.figures.NAME``); commands, not library API."""
