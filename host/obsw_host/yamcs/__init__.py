"""Mission control with Yamcs: XTCE from the spacecraft database, instances, links."""
