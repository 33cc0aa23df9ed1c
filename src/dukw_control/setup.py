from setuptools import find_packages, setup

package_name = 'dukw_control'

setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['test']),
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='DUKW-Ling team',
    maintainer_email='dev@dukw-ling.invalid',
    description="Mode manager and differential-drive controller with the vehicle's limits.",
    license='Apache-2.0',
    tests_require=['pytest'],
    entry_points={
        'console_scripts': [
            'mode_manager_node = dukw_control.mode_manager_node:main',
            'drive_controller_node = dukw_control.drive_controller_node:main',
            'maneuver_node = dukw_control.maneuver_node:main',
        ],
    },
)
