"""Host side of the reconfiguration module: the simulated module (two MicroPython controller
processes on shared simulated lines, EEPROM and RTC models, ptys, a CAN hub) and the OBC."""
