"""Host command modules for the obsw CLI."""
