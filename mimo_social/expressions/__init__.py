"""Facial expressions: face textures drawn in code and the per-agent expression switch."""
