"""CCSDS space data link: TC and TM frames, CLTU with BCH, COP-1, ASM, randomizer, processor."""
