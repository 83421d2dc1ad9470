"""Rendering and writing: strict Jinja2 environments, one-unit writes."""
