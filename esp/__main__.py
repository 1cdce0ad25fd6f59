from esp.cli import main

main(prog_name="esp")
