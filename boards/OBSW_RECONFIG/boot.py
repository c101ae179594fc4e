# boot.py: runs first after every reset. USB stays a serial REPL plus the flash drive so
# `obsw board deploy/repl/test` can reach the board; the application starts from main.py.
import pyb

pyb.usb_mode("VCP+MSC")
