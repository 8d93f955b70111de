"""SDF text for the world and CLI tests: a Gazebo-shaped world file and the SDF lesson's box."""

from __future__ import annotations

# A world in Gazebo's usual shape: stock includes, a custom <physics>, Moon gravity, two models
# (one with a nested model placed relative_to a link of its parent).
WORLD = """<?xml version="1.0"?>
<sdf version="1.8">
  <world name="moon_lab">
    <physics name="fast" type="ode">
      <max_step_size>0.002</max_step_size>
      <real_time_update_rate>500</real_time_update_rate>
      <ode><solver><type>quick</type><iters>80</iters></solver></ode>
    </physics>
    <gravity>0 0 -1.62</gravity>
    <include><uri>model://ground_plane</uri></include>
    <include><uri>model://sun</uri></include>
    <model name="crate">
      <pose>1 0 2 0 0 0</pose>
      <link name="body">
        <inertial><mass>5</mass>
          <inertia><ixx>0.075</ixx><iyy>0.075</iyy><izz>0.075</izz></inertia></inertial>
        <collision name="c"><geometry><box><size>0.3 0.3 0.3</size></box></geometry></collision>
      </link>
    </model>
    <model name="table">
      <static>true</static>
      <pose>-1 0.5 0 0 0 0.5</pose>
      <link name="top">
        <pose>0 0 0.7 0 0 0</pose>
        <collision name="c"><geometry><box><size>1 1 0.05</size></box></geometry></collision>
      </link>
      <model name="lamp">
        <pose relative_to="top">0.2 0 0.1 0 0 0</pose>
        <link name="bulb">
          <collision name="c">
            <geometry><sphere><radius>0.05</radius></sphere></geometry>
          </collision>
        </link>
      </model>
    </model>
  </world>
</sdf>
"""

LESSON_BOX = """<sdf version="1.6"><model name="test_box"><static>true</static><link name="link">
  <collision name="collision"><geometry><box><size>0.5 0.5 0.5</size></box></geometry></collision>
  <visual name="visual"><geometry><box><size>0.5 0.5 0.5</size></box></geometry>
    <material><script><uri>file://media/materials/scripts/gazebo.material</uri>
    <name>Gazebo/Red</name></script></material></visual></link></model></sdf>"""
