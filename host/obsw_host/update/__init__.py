"""Signed software updates (``obsw.update.package``): packages, the OBC's software slots."""
