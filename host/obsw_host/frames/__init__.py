"""Host side of the space data link: the frame processor on two serial ports, and the ground."""
