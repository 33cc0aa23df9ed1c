from glob import glob

from setuptools import find_packages, setup

package_name = 'dukw_common'

setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['test']),
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
        # The workspace's parameter files, so installed nodes find their defaults.
        ('share/' + package_name + '/config', glob('config/*.yaml')),
        ('share/' + package_name + '/config/reference', glob('config/reference/*.yaml')),
        ('share/' + package_name + '/config/sros2', glob('config/sros2/*.xml')),
        ('share/' + package_name + '/config/sros2/profiles',
         glob('config/sros2/profiles/*.xml')),
    ],
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='DUKW-Ling team',
    maintainer_email='dev@dukw-ling.invalid',
    description='Shared parameter loading, vehicle facts and rclpy helpers of the stack.',
    license='Apache-2.0',
    tests_require=['pytest'],
    entry_points={'console_scripts': []},
)
