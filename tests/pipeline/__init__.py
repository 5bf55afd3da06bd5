"""The task pipeline, driven without the daemon or its socket."""
