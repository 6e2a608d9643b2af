"""Imported by LeRobot's plugin discovery: registers lerobot-phantom with LeRobot on import.

``--<anything>.discover_packages_path=lerobot_phantom`` makes a stock ``lerobot-*`` script (LeRobot 0.4.4,
``lerobot.configs.parser.load_plugin``) import ``lerobot_phantom`` and then every module and subpackage directly
under it, before it parses the command line. This module is one of them; importing it is the only side effect it
has. Importing ``lerobot_phantom`` itself registers nothing, so that the attacks stay usable without LeRobot.
"""

from lerobot_phantom import register

register()
