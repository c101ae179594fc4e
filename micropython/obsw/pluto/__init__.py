"""Compact PLUTO (ECSS-E-ST-70-32C) lexer, parser, load-time checker and step-wise interpreter."""
