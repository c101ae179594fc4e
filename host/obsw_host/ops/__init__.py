"""Operations across passes: the orbit and the ground stations of the mission file, pass
prediction (``passes``), and pass plans as service 11 time-tagged commands (``plan``)."""
