"""One module per `rover` command; each exposes `register(app)`."""
