"""The physical world of pick and place (issue 20): gripper, belts, parts and tray on a
discrete MultibodyPlant with contact.  ``config`` holds the typed settings,
``station.MakePickStation`` builds the station, ``world.PickWorld`` is the world
(``worlds.base``), ``scene`` adds the non-arm bodies and
``part_pose`` exports each part's simulated pose as a target."""
