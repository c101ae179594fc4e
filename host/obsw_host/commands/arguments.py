"""Argument types the commands share: argparse refuses a bad value with a one-line error."""

import argparse


def seconds(text):
    """A duration in seconds, > 0."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError("%r is not a number of seconds" % text) from None
    if not value > 0 or value == float("inf"):
        raise argparse.ArgumentTypeError("%s: expected a number of seconds > 0" % text)
    return value


def count(text):
    """A count of things, >= 1."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError("%r is not an integer" % text) from None
    if value < 1:
        raise argparse.ArgumentTypeError("%s: expected an integer >= 1" % text)
    return value
