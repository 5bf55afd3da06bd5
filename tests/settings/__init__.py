"""Settings read through agent/settings.py."""
