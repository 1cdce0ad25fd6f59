from esp.cli import run

run()
