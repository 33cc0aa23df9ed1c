from setuptools import find_packages, setup

package_name = 'dukw_driver'

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
    description='Hardware nodes: servo switch, motor controllers, IMU/DGPS, water sensors.',
    license='Apache-2.0',
    tests_require=['pytest'],
    entry_points={
        'console_scripts': [
            'servo_switch_node = dukw_driver.servo_switch_node:main',
            'motor_controller_node = dukw_driver.motor_controller_node:main',
            'imu_gps_node = dukw_driver.imu_gps_node:main',
            'water_sensor_node = dukw_driver.water_sensor_node:main',
            'shore_link_node = dukw_driver.shore_link_node:main',
        ],
    },
)
