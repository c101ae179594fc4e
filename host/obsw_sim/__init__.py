"""Rigs and simulations around the product: the twelve-step chain, the chaos campaign, the
simulated reconfiguration module, watchdog and update rig. Tests, benchmarks and the demo use
them; the product (``obsw_host``) never imports this package (a test checks)."""
