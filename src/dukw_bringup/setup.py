from glob import glob

from setuptools import find_packages, setup

package_name = 'dukw_bringup'

setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['test']),
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
        ('share/' + package_name + '/launch', glob('launch/*.py')),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='DUKW-Ling team',
    maintainer_email='dev@dukw-ling.invalid',
    description='Bring-up of the DUKW-Ling stack: runner, launch files, mission, rosbag2 tools.',
    license='Apache-2.0',
    tests_require=['pytest'],
    entry_points={
        'console_scripts': [
            # main job and bring-up (issue 7, bring-up helper)
            'bringup = dukw_bringup.bringup:main',
            'compose = dukw_bringup.compose:main',
            'mission_node = dukw_bringup.mission_node:main',
            'robot_state_node = dukw_bringup.robot_state_node:main',
            'live_view_node = dukw_bringup.live_view_node:main',
            'main_job = dukw_bringup.main_job:main',
            'plot_run = dukw_bringup.plot_run:main',
            # rosbag2 tools (issue 7, bag helper)
            'record = dukw_bringup.record:main',
            'play = dukw_bringup.play:main',
            'replay = dukw_bringup.replay:main',
            'evaluate = dukw_bringup.evaluate:main',
            # randomized runs on Dask (issue 18)
            'campaign = dukw_bringup.campaign_cli:main',
            'campaign_compare = dukw_bringup.campaign_compare:main',
        ],
    },
)
