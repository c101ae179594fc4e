"""SpaceCAN on the host: python-can adapter, fault injection, frame monitor and the demo."""
