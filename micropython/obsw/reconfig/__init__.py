"""The reconfiguration module: CPDU, safeguard memory, DS3231 time, watchdog, essential TC/TM.

Core logic only; the hardware comes in through a hardware layer (`obsw.reconfig.hal`).
"""
