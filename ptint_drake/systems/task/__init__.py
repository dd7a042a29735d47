"""The task in space and time: the schedule of segments (``schedule``), the time base generator
(``tbg``, paper eqs. 6-10), the targets x_r(t) (``targets``), the task error (``error``, paper
eq. 11) with its orientation (``orientation``), the arm's task-space kinematics (``kinematics``,
paper eq. 5; ``chain`` compiled), and the named slots and cached vectors the blocks pass
(``signals``, ``cache``, ``views``, ``active_segment``)."""
