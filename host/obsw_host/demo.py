"""The demo: every capability of the system, simulated on one machine."""


def main():
    print("obsw demo")
    return 0
