"""Settings read through rsl/settings.py."""
