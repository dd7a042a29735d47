"""The catch world (issue 46): a thrown foam ball caught in the hand of the KUKA iiwa 14 with the
full-size Schunk WSG 50-110 at a time the planner chooses.  ``ball`` holds the ball's model, the
truth side's air drag and the drop test of its restitution."""
